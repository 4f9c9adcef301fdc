"""app/accuracy/metrics.py (relMAE, FLIP, heat maps) and ``alight compare``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from alight.accuracy.metrics import (
    COLORBAR_HEIGHT,
    compare_linear,
    covered_mask,
    flip,
    heatmap_size,
    relative_error_map,
    relative_mae,
    tonemapped_srgb,
    write_relative_heatmap,
)
from alight.exchange.output import write_image

REPO = Path(__file__).resolve().parents[1]


def probe_like(size=32, seed=0) -> np.ndarray:
    """A linear RGBA image: a disk of smooth positive radiance, alpha 1 inside, 0 (and black) outside."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size]
    u, v = (x + 0.5) / size * 2 - 1, 1 - (y + 0.5) / size * 2
    inside = u * u + v * v < 1
    img = np.zeros((size, size, 4), np.float32)
    img[..., 0] = 0.5 + 0.4 * u
    img[..., 1] = 0.3 + 0.2 * v
    img[..., 2] = 0.2 + rng.uniform(0.0, 0.1, (size, size))
    img[..., :3] *= inside[..., None]
    img[..., 3] = inside
    return img


def test_identical_images_have_zero_error():
    ref = probe_like()
    assert relative_mae(ref, ref.copy()) == 0.0
    assert np.all(relative_error_map(ref, ref) == 0.0)
    c = compare_linear(ref, ref.copy())
    assert c.relative_mae == 0.0
    assert c.flip == 0.0
    assert c.covered == int((ref[..., 3] > 0).sum())


def test_a_known_scale_gives_a_known_relmae():
    ref = probe_like()
    test = ref.copy()
    test[..., :3] *= 1.1                           # 10% brighter everywhere
    assert relative_mae(test, ref) == pytest.approx(0.1, rel=1e-5)
    test = ref.copy()
    test[..., 1] += 0.05 * test[..., 3]            # +0.05 on green over the covered pixels
    mask = ref[..., 3] > 0
    expected = 0.05 * mask.sum() / ref[..., :3][mask].sum()
    assert relative_mae(test, ref) == pytest.approx(expected, rel=1e-5)
    per_pixel = relative_error_map(test, ref)
    assert per_pixel[mask] == pytest.approx(0.05 / ref[..., :3][mask].sum(axis=1), rel=1e-4)
    assert np.all(per_pixel[~mask] == 0.0)


def test_uncovered_pixels_do_not_count():
    ref = probe_like()
    test = ref.copy()
    outside = ref[..., 3] == 0
    test[outside, :3] = 100.0                      # garbage where alpha is 0
    assert relative_mae(test, ref) == 0.0
    assert covered_mask(ref).sum() == (~outside).sum()
    # Without alpha every pixel counts.
    assert relative_mae(test[..., :3], ref[..., :3]) > 1.0


def test_flip_is_zero_for_identical_and_positive_for_a_change():
    ref = tonemapped_srgb(probe_like())
    mean, fmap = flip(ref, ref.copy())
    assert mean == 0.0 and fmap.shape == ref.shape[:2] and np.all(fmap == 0.0)
    changed = ref.copy()
    changed[8:16, 8:16] = 1.0 - changed[8:16, 8:16]
    mean2, fmap2 = flip(changed, ref)
    assert mean2 > 0.0
    assert fmap2[8:16, 8:16].mean() > 10 * max(fmap2[20:, 20:].mean(), 1e-6)   # the error is where the change is


def test_heatmap_is_written_atomically_with_the_right_size(tmp_path, monkeypatch):
    import OpenImageIO as oiio

    ref = probe_like(40)
    test = ref.copy()
    test[..., :3] *= 1.2
    out = tmp_path / "rel.png"
    write_relative_heatmap(out, relative_error_map(test, ref))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rel.png"]    # no temporary file left
    spec = oiio.ImageInput.open(str(out)).spec()
    assert (spec.width, spec.height) == heatmap_size(40, 40)
    assert spec.height - COLORBAR_HEIGHT == spec.width * 40 // 40        # the map is square above its bar
    buf = oiio.ImageBuf(str(out))
    px = buf.get_pixels(oiio.UINT8)
    s = spec.width // 40
    centre = px[20 * s, 20 * s, :3].astype(int)    # 20% error: a lit colour, not the 0 colour
    corner = px[0, 0, :3].astype(int)              # uncovered: 0 error
    assert np.abs(centre - corner).sum() > 60
    # A write that fails half way leaves nothing behind and keeps the old file.
    from matplotlib.figure import Figure

    def broken_savefig(self, fname, **kwargs):
        Path(fname).write_bytes(b"\x89PNG half")
        raise OSError("disk full")

    before = out.read_bytes()
    monkeypatch.setattr(Figure, "savefig", broken_savefig)
    with pytest.raises(OSError):
        write_relative_heatmap(out, relative_error_map(test, ref))
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rel.png"]


# --- alight compare ------------------------------------------------------------------------

def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=120)


def test_compare_cli_measures_and_writes_heatmaps(tmp_path):
    ref = probe_like(48)
    test = ref.copy()
    test[..., :3] *= 1.1
    write_image(tmp_path / "ref.exr", ref, linear=True)
    write_image(tmp_path / "test.exr", test, linear=True)
    proc = run("compare", tmp_path / "test.exr", tmp_path / "ref.exr", "--heatmap", tmp_path / "rel.png",
               "--flip-heatmap", tmp_path / "flip.png")
    assert proc.returncode == 0, proc.stderr
    assert "relMAE 10%" in proc.stdout, proc.stdout
    flip_value = float(proc.stdout.split("FLIP ")[1].split()[0])
    assert flip_value > 0.0
    assert (tmp_path / "rel.png").is_file() and (tmp_path / "flip.png").is_file()
    same = run("compare", tmp_path / "ref.exr", tmp_path / "ref.exr")
    assert same.returncode == 0 and "relMAE 0%  FLIP 0 " in same.stdout, same.stdout


@pytest.mark.parametrize("case", ["missing", "png", "size", "garbage"])
def test_compare_cli_refuses_bad_files_in_one_line(tmp_path, case):
    ref = probe_like(16)
    write_image(tmp_path / "ref.exr", ref, linear=True)
    if case == "missing":
        bad = tmp_path / "nope.exr"
    elif case == "png":
        bad = tmp_path / "x.png"
        write_image(bad, (tonemapped_srgb(ref) * 255).astype(np.uint8), linear=False)
    elif case == "size":
        bad = tmp_path / "small.exr"
        write_image(bad, probe_like(8), linear=True)
    else:
        bad = tmp_path / "garbage.exr"
        bad.write_bytes(b"not an exr at all")
    proc = run("compare", bad, tmp_path / "ref.exr", "--heatmap", tmp_path / "h.png")
    assert proc.returncode == 2
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("alight: error: ") and bad.name in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "h.png").exists()

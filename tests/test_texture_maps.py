"""User-loaded texture maps (app/core/texture_maps.py) in the forward pass."""

from __future__ import annotations

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import sphere
from alight.core.scene import Light, Scene
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.exchange.images import load_map_image
from alight.exchange.output import write_image
from alight.ibl.environment import load_environment
from tests.gpu import renderer


def checker(path, cells: int = 8, size: int = 256, low: int = 20, high: int = 235) -> str:
    i, j = np.indices((size, size)) * cells // size
    grey = np.where((i + j) % 2 == 0, low, high).astype(np.uint8)
    write_image(str(path), np.repeat(grey[:, :, None], 3, axis=2), linear=False)
    return str(path)


def flat(path, value: int, size: int = 16) -> str:
    write_image(str(path), np.full((size, size, 3), value, np.uint8), linear=False)
    return str(path)


def draw(maps: TextureMaps | None, images: dict, material: Material | None = None, size: int = 128,
         env: str = "studio") -> np.ndarray:
    r = renderer()
    ibl = r.bake(load_environment(env), "low")
    scene = Scene(mesh=sphere(), material=material or Material(base_color=(0.8, 0.8, 0.8), roughness=0.6),
                  use_file_materials=False, texture_maps=maps, texture_images=images,
                  lights=[Light("point", (2.0, 3.0, 4.0), intensity=20.0)])
    return r.render(scene, ibl, size, size, aa="none").linear


def disk(image: np.ndarray, radius: float = 0.25) -> np.ndarray:
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    return image[(x - w / 2) ** 2 + (y - h / 2) ** 2 < (radius * h) ** 2]


def steps(image: np.ndarray) -> float:
    """Mean luminance step between horizontal neighbours inside the ball: the shading's smooth
    gradient gives small steps, a pattern's edges big ones."""
    lum = image[:, :, :3].mean(axis=2)
    step = np.zeros_like(lum)
    step[:, 1:] = np.abs(np.diff(lum, axis=1))
    return float(disk(step[:, :, None]).mean())


def test_map_image_reading(tmp_path):
    grey = load_map_image(flat(tmp_path / "g.png", 77))
    assert grey.shape == (16, 16, 4) and grey.dtype == np.uint8
    assert (grey[:, :, :3] == 77).all() and (grey[:, :, 3] == 255).all()
    bad = tmp_path / "broken.png"
    bad.write_bytes(b"\x89PNG\r\n\x1a\n" + b"garbage" * 20)
    for path, words in ((bad, "broken.png"), (tmp_path / "missing.png", "no such file"), (tmp_path, "directory")):
        with pytest.raises(AlightError) as info:
            load_map_image(str(path))
        assert words in str(info.value) and "\n" not in str(info.value)


def test_checker_base_colour_varies_and_clear_restores(tmp_path):
    path = checker(tmp_path / "checker.png")
    images = {path: load_map_image(path)}
    plain = draw(None, {})
    mapped = draw(TextureMaps(base_color=path), images)
    cleared = draw(TextureMaps(), images)
    assert steps(mapped) > 3.0 * steps(plain)
    assert np.abs(cleared - plain).max() < 1e-6


def test_tiling_multiplies_the_pattern_frequency(tmp_path):
    """Four times the tiling, about four times the checker's edges: measured on the image
    divided by the unmapped one, so that the shading's own gradient cancels."""
    path = checker(tmp_path / "checker.png")
    images = {path: load_map_image(path)}
    plain = draw(None, {}, size=192)
    albedo = {}
    for scale in (1.0, 4.0):
        mapped = draw(TextureMaps(base_color=path, uv_scale=(scale, scale)), images, size=192)
        albedo[scale] = np.where(plain > 1e-4, mapped / np.maximum(plain, 1e-4), 0.0)
    ratio = steps(albedo[4.0]) / steps(albedo[1.0])
    assert 2.5 < ratio < 6.0, ratio


def test_separate_roughness_and_metallic_maps(tmp_path):
    """A greyscale roughness map of 0.1 on a roughness-1 material sharpens the highlight; a
    metallic map of 0 on a gold metal leaves a grey (dielectric) reflection."""
    smooth = flat(tmp_path / "r.png", 26)   # 26/255 ~ 0.1
    images = {smooth: load_map_image(smooth)}
    rough = Material(base_color=(0.8, 0.8, 0.8), roughness=1.0, metallic=0.0)
    without = draw(None, {}, rough)
    with_map = draw(TextureMaps(roughness=smooth), images, rough)
    assert disk(with_map).max() > 3.0 * disk(without).max()
    # The same value through glTF's packed map (G = roughness) gives the same image.
    packed = tmp_path / "mr.png"
    write_image(str(packed), np.dstack([np.zeros((16, 16), np.uint8), np.full((16, 16), 26, np.uint8),
                                        np.full((16, 16), 255, np.uint8)]), linear=False)
    images[str(packed)] = load_map_image(str(packed))
    assert np.abs(draw(TextureMaps(metallic_roughness=str(packed)), images, rough) - with_map).max() < 1e-5

    black = flat(tmp_path / "m.png", 0)
    images[black] = load_map_image(black)
    gold = Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.3)
    metal = draw(None, {}, gold)
    mapped = draw(TextureMaps(metallic=black), images, gold)
    dielectric = draw(None, {}, Material(base_color=gold.base_color, metallic=0.0, roughness=0.3))
    assert np.abs(mapped - dielectric).max() < 1e-5
    assert np.abs(disk(metal) - disk(mapped)).mean() > 0.05

"""Every field of the material-field registry is accepted by every front end, and does the same.

For each field of ``alight.core.material_fields.FIELDS`` the test renders the sphere with
``alight render --FLAG VALUE`` and, in one ``alight batch`` run, the same material as a spec
table: the two PNGs must be equal, and must differ from the batch's picture of the same
material without the field (so the field reached the shader through both doors).
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from alight.core.material import Material
from alight.core.material_fields import BY_NAME, FIELDS, NAMES
from alight.errors import AlightError

# (value, the other fields it needs to show) per registry field: a layer's second field shows
# only with the layer on, the volume only through transmission. A field added to the registry
# fails test_every_field_has_a_case until it has a line here.
_DARK = (0.05, 0.05, 0.05)
_VOLUME = dict(transmission=1.0, thickness=1.0, attenuation_color=(1.0, 0.2, 0.2), attenuation_distance=0.5)
CASES: dict[str, tuple[object, dict]] = {
    "base_color": ((0.9, 0.2, 0.1), {}),
    "metallic": (1.0, {}),
    "roughness": (0.1, {}),
    "specular_f0": ((0.5, 0.5, 0.5), {}),
    "emissive": ((1.0, 0.5, 0.0), {}),
    "ior": (2.5, {}),
    "clearcoat": (1.0, {"base_color": _DARK}),
    "clearcoat_roughness": (0.8, {"base_color": _DARK, "clearcoat": 1.0}),
    "sheen_color": ((1.0, 1.0, 1.0), {"base_color": _DARK, "sheen_roughness": 0.5}),
    "sheen_roughness": (0.9, {"base_color": _DARK, "sheen_color": (1.0, 1.0, 1.0)}),
    "anisotropy_strength": (1.0, {"metallic": 1.0, "roughness": 0.4}),
    "anisotropy_rotation": (1.2, {"metallic": 1.0, "roughness": 0.4, "anisotropy_strength": 1.0}),
    "transmission": (1.0, {}),
    "thickness": (1.0, {k: v for k, v in _VOLUME.items() if k != "thickness"}),
    "attenuation_color": ((1.0, 0.2, 0.2), {k: v for k, v in _VOLUME.items() if k != "attenuation_color"}),
    "attenuation_distance": (0.3, {k: v for k, v in _VOLUME.items() if k != "attenuation_distance"}),
    "iridescence": (1.0, {"base_color": _DARK, "iridescence_ior": 1.8}),
    "iridescence_ior": (2.0, {"base_color": _DARK, "iridescence": 1.0}),
    "iridescence_thickness_minimum": (300.0, {"base_color": _DARK, "iridescence": 1.0}),
    "iridescence_thickness_maximum": (250.0, {"base_color": _DARK, "iridescence": 1.0, "iridescence_ior": 1.8}),
    "diffuse_transmission": (1.0, {"base_color": (0.9, 0.2, 0.1), "diffuse_transmission_color": (0.1, 0.2, 0.9)}),
    "diffuse_transmission_color": ((0.1, 0.2, 0.9), {"base_color": (0.9, 0.2, 0.1), "diffuse_transmission": 1.0}),
    "dispersion": (10.0, {"transmission": 1.0, "thickness": 1.0, "ior": 3.0, "roughness": 0.2}),
}
# Fields that change the picture only through a map (the thickness map's G mixes minimum and
# maximum; without one the film is the maximum thick): both front ends must still agree.
_ONLY_WITH_A_MAP = ("iridescence_thickness_minimum",)
_SETTINGS = ["--size", "32", "--quality", "low", "--aa", "none"]
_SPEC_SETTINGS = {"size": 32, "quality": "low", "aa": "none"}


def _flag_value(value) -> str:
    return ",".join(f"{c:g}" for c in value) if isinstance(value, tuple) else f"{value:g}"


def _alight(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *args], capture_output=True, text=True,
                          timeout=300, cwd=cwd)


def _png(path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.int16)


def test_registry_is_the_material_dataclass():
    """One field per Material field (but its name), with the dataclass's defaults and the
    model's ranges; layers carry their glTF extension."""
    assert set(NAMES) == {f.name for f in dataclasses.fields(Material)} - {"name"}
    for f in FIELDS:
        assert f.default == Material.__dataclass_fields__[f.name].default
        assert f.low <= f.high and f.help and f.flag == "--" + f.name.replace("_", "-")
        assert (f.layer is None) == (f.extension is None or f.name in ("ior", "specular_f0"))
    assert BY_NAME["clearcoat"].extension == "KHR_materials_clearcoat"
    assert BY_NAME["sheen_color"].kind == "color" and BY_NAME["ior"].low == 1.0


def test_every_field_has_a_case():
    assert set(CASES) == set(NAMES)


def test_cli_and_batch_accept_every_field_and_render_it_alike(tmp_path):
    materials = []
    for name in NAMES:
        value, context = CASES[name]
        materials.append({"name": f"with_{name}", **context, name: value})
        materials.append({"name": f"without_{name}", **context})
    spec = tmp_path / "fields.json"   # JSON: the batch reads it like TOML, and json writes tuples as arrays
    spec.write_text(json.dumps({**_SPEC_SETTINGS, "out": "out", "materials": materials, "contact_sheet": False}))
    r = _alight("batch", str(spec))
    assert r.returncode == 0, r.stderr
    out = tmp_path / "out"

    def batch_png(label: str) -> np.ndarray:
        return _png(out / f"sphere__studio__{label}__cam000_env000.png")

    for name in NAMES:
        value, context = CASES[name]
        flags = [a for k, v in {**context, name: value}.items() for a in (BY_NAME[k].flag, _flag_value(v))]
        png = tmp_path / f"render_{name}.png"
        r = _alight("render", *_SETTINGS, *flags, "--out", str(png))
        assert r.returncode == 0, f"alight render {' '.join(flags)}: {r.stderr}"
        cli, batch, without = _png(png), batch_png(f"with_{name}"), batch_png(f"without_{name}")
        assert np.array_equal(cli, batch), f"{name}: alight render and alight batch differ " \
                                           f"(max {np.abs(cli - batch).max()})"
        changed = np.abs(batch - without).max(axis=-1) > 2
        if name in _ONLY_WITH_A_MAP:
            assert not changed.any(), f"{name}={value} changed a picture without a map"
            continue
        assert changed.mean() > 0.01, f"{name}={value}: the picture did not change ({changed.mean():.1%} of pixels)"


def test_batch_refuses_a_bad_value_before_rendering(tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text('size = 32\nmaterials = [{name = "c", clearcoat = 1.5}]\n')
    r = _alight("batch", str(spec))
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "clearcoat" in r.stderr and "out of range" in r.stderr and "bad.toml" in r.stderr
    assert not (tmp_path / "bad").exists()


def test_api_names_the_fields_on_an_unknown_keyword():
    from alight.frontends.api import Renderer

    with pytest.raises(AlightError, match=r"unknown field 'rougness' \(did you mean 'roughness'\? the fields: base_color, .*clearcoat"):
        Renderer(width=8, height=8).set_material(rougness=0.3)

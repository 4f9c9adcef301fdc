"""The names both languages share come from app/core/shader_names.py: every name a shader's
preprocessor tests is generated there, declared there as an option Python passes, or defined by a
shader itself; enum-valued options are compared with generated names, never with bare numbers."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from alight.core import shader_names as sn
from alight.core.gpu import ShaderCompileError, load_source
from alight.core.ibl_models import IBL_MODELS
from alight.core.mesh import ALPHA_MODES
from alight.core.scene import BACKGROUNDS, LIGHT_KINDS, TONEMAPS

SHADERS = Path(__file__).resolve().parents[1] / "shaders"
SOURCES = {p: p.read_text(encoding="utf-8") for p in SHADERS.rglob("*") if p.suffix in (".glsl", ".comp", ".frag", ".vert")}
_DIRECTIVE = re.compile(r"^\s*#\s*(if|elif|ifdef|ifndef)\b(.*)$", re.M)
_DEFINE = re.compile(r"^\s*#\s*define\s+([A-Za-z_]\w*)", re.M)
_IDENT = re.compile(r"\b([A-Za-z_]\w*)\b")
# Options whose value is one of an enum's members.
ENUM_OPTIONS = {"IBL_MODEL": sn.IblModel, "ALPHA_MODE": sn.AlphaMode, "BACKGROUND_MODE": sn.BackgroundMode,
                "TONEMAP_MODE": sn.Tonemap}


def _code(text: str) -> str:
    """The text without // and /* */ comments."""
    return re.sub(r"//[^\n]*|/\*.*?\*/", "", text, flags=re.S)


def _tested_names() -> dict[str, set[Path]]:
    names: dict[str, set[Path]] = {}
    for path, text in SOURCES.items():
        for _, expr in _DIRECTIVE.findall(_code(text)):
            for name in _IDENT.findall(expr):
                if name != "defined":
                    names.setdefault(name, set()).add(path)
    return names


def _shader_defined() -> set[str]:
    return {name for text in SOURCES.values() for name in _DEFINE.findall(_code(text))}


def test_every_name_a_shader_tests_has_one_source():
    generated = set(sn.glsl_defines())
    known = generated | set(sn.SHADER_OPTIONS) | _shader_defined()
    unknown = {name: sorted(str(p.relative_to(SHADERS)) for p in paths)
               for name, paths in _tested_names().items() if name not in known}
    assert not unknown, f"names tested by shaders but neither generated nor declared: {unknown}"


def test_every_declared_option_is_read_by_a_shader():
    code = "\n".join(_code(t) for t in SOURCES.values())
    unused = [name for name in sn.SHADER_OPTIONS if not re.search(rf"\b{name}\b", code)]
    assert not unused, f"SHADER_OPTIONS no shader reads: {unused}"


def test_shaders_do_not_redefine_generated_names():
    generated = set(sn.glsl_defines())
    for path, text in SOURCES.items():
        code = _code(text)
        redefined = generated & set(_DEFINE.findall(code))
        consts = {m for m in re.findall(r"\bconst\s+int\s+(\w+)\s*=", code) if m in generated}
        assert not redefined | consts, f"{path.relative_to(SHADERS)} defines generated names {sorted(redefined | consts)}"


def test_enum_options_are_compared_with_names_not_numbers():
    for path, text in SOURCES.items():
        for _, expr in _DIRECTIVE.findall(_code(text)):
            for option in ENUM_OPTIONS:
                bare = re.search(rf"\b{option}\s*[!=]=\s*\d", expr)
                assert not bare, f"{path.relative_to(SHADERS)}: '{expr.strip()}' compares {option} with a number"
    debug = _code((SHADERS / "common/debug_views.glsl").read_text())
    assert not re.search(r"\bcase\s+\d", debug), "debug views are chosen by DEBUG_VIEW_* names"


def test_raw_map_masks_are_gone():
    """The bits of MATERIAL_MAPS_MASK are the generated MAP_* names, not numbers like 98304."""
    code = _code((SHADERS / "common/mesh_material.glsl").read_text())
    assert not re.search(r"MATERIAL_MAPS_MASK\s*&\s*\d", code)
    assert not re.search(r"#define MATERIAL_MAPS_MASK \d", code)


def test_enums_follow_the_python_tuples():
    assert [m.value for m in sn.IblModel] == list(range(len(IBL_MODELS)))
    assert [sn.glsl_member(sn.IblModel, name) for name in IBL_MODELS] == list(sn.IblModel)
    assert [sn.glsl_member(sn.Tonemap, name) for name in TONEMAPS] == list(sn.Tonemap)
    assert [sn.glsl_member(sn.BackgroundMode, name) for name in BACKGROUNDS] == list(sn.BackgroundMode)
    assert [sn.glsl_member(sn.LightKind, name) for name in LIGHT_KINDS] == list(sn.LightKind)
    assert [sn.glsl_member(sn.AlphaMode, name) for name in ALPHA_MODES] == list(sn.AlphaMode)
    assert sn.map_mask(sn.MATERIAL_MAPS) == sn.glsl_defines()["MAP_ALL"]
    assert sn.glsl_defines()["MAP_SPECULAR_COLOR"] == 1 << sn.MATERIAL_MAPS.index("specular_color")
    with pytest.raises(ValueError, match="known: lecture"):
        sn.glsl_member(sn.IblModel, "nonsense")


def test_every_shader_gets_the_generated_names():
    text = load_source("render/pbr.frag", {"IBL_MODEL": int(sn.IblModel.STRETCHED)}).text
    lines = text.splitlines()
    assert lines[0].startswith("#version")
    assert "#define IBL_MODEL_STRETCHED 5" in lines
    assert lines.index("#define IBL_MODEL_STRETCHED 5") < lines.index("#define IBL_MODEL 5")


def test_an_undeclared_option_is_refused():
    with pytest.raises(ShaderCompileError, match="HAS_CLEARCOT"):
        load_source("render/pbr.frag", {"HAS_CLEARCOT": None})

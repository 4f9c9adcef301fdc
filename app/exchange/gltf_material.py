"""glTF material round trip: a glTF/GLB material into alight.core.material.Material, and back out as a
material-only ``.gltf`` (a mesh with the material and its maps: alight.exchange.gltf_export).

The two models meet like this (glTF 2.0 core, KHR_materials_ior, KHR_materials_specular,
KHR_materials_emissive_strength):

    base_color  = baseColorFactor.rgb          (alpha is dropped: the model is opaque)
    metallic    = metallicFactor, roughness = roughnessFactor
    emissive    = emissiveFactor * emissiveStrength
    ior         = ior
    specular_f0 = min(((ior - 1) / (ior + 1))^2 * specularColorFactor, 1) * specularFactor

Export inverts the last lines exactly: the material's ior goes out as KHR_materials_ior
(when not 1.5), and a specular_f0 other than the ior's F0 as specularColorFactor = F0 / F0(ior)
(KHR_materials_specular allows factors above 1; the formula's min(..., 1) then clamps), so
engines that know the extensions shade the same dielectric reflectance. The ior rule of
alight.core.material makes a grey F0 other than 0.04 an ior of its own: water's 0.02 is ior
1.33, written as such.

The layers (docs/layers.md) are the extensions' factors, one to one:

    transmission          = KHR_materials_transmission.transmissionFactor
    thickness             = KHR_materials_volume.thicknessFactor
    attenuation_color     = KHR_materials_volume.attenuationColor
    attenuation_distance  = KHR_materials_volume.attenuationDistance (absent: +inf)
    dispersion            = KHR_materials_dispersion.dispersion
    diffuse_transmission  = KHR_materials_diffuse_transmission.diffuseTransmissionFactor
    diffuse_transmission_color = KHR_materials_diffuse_transmission.diffuseTransmissionColorFactor
    clearcoat             = KHR_materials_clearcoat.clearcoatFactor
    clearcoat_roughness   = KHR_materials_clearcoat.clearcoatRoughnessFactor
    sheen_color           = KHR_materials_sheen.sheenColorFactor
    sheen_roughness       = KHR_materials_sheen.sheenRoughnessFactor
    anisotropy_strength   = KHR_materials_anisotropy.anisotropyStrength
    anisotropy_rotation   = KHR_materials_anisotropy.anisotropyRotation
    iridescence           = KHR_materials_iridescence.iridescenceFactor
    iridescence_ior       = KHR_materials_iridescence.iridescenceIor
    iridescence_thickness_minimum, _maximum = KHR_materials_iridescence.iridescenceThicknessMinimum, _Maximum

An extension is written only when one of its fields differs from its default (the layer is
on). The factors only: a material's maps (alight.core.texture_maps) are written by
alight.exchange.gltf_export and read back by alight.exchange.material_files.
"""

from __future__ import annotations

import json
import math
import os
import struct
from pathlib import Path
from typing import Any


from alight.core.material import DEFAULT_IOR, Material, f0_from_ior, validate_material
from alight.errors import AlightError
from alight.exchange.output import atomic_path

EXT_IOR = "KHR_materials_ior"
EXT_SPECULAR = "KHR_materials_specular"
EXT_EMISSIVE = "KHR_materials_emissive_strength"
EXT_TRANSMISSION = "KHR_materials_transmission"
EXT_VOLUME = "KHR_materials_volume"
EXT_CLEARCOAT = "KHR_materials_clearcoat"
EXT_SHEEN = "KHR_materials_sheen"
EXT_ANISOTROPY = "KHR_materials_anisotropy"
EXT_IRIDESCENCE = "KHR_materials_iridescence"
EXT_DISPERSION = "KHR_materials_dispersion"
EXT_DIFFUSE_TRANSMISSION = "KHR_materials_diffuse_transmission"
DEFAULT_F0 = 0.04  # ((1.5 - 1) / (1.5 + 1))^2, glTF's default dielectric
# Each layer extension's factors: (glTF name, Material field, glTF default, components).
LAYER_EXTENSIONS: dict[str, tuple[tuple[str, str, Any, int], ...]] = {
    EXT_TRANSMISSION: (("transmissionFactor", "transmission", 0.0, 1),),
    EXT_VOLUME: (("thicknessFactor", "thickness", 0.0, 1),
                 ("attenuationDistance", "attenuation_distance", math.inf, 1),
                 ("attenuationColor", "attenuation_color", (1.0, 1.0, 1.0), 3)),
    EXT_CLEARCOAT: (("clearcoatFactor", "clearcoat", 0.0, 1),
                    ("clearcoatRoughnessFactor", "clearcoat_roughness", 0.0, 1)),
    EXT_SHEEN: (("sheenColorFactor", "sheen_color", (0.0, 0.0, 0.0), 3),
                ("sheenRoughnessFactor", "sheen_roughness", 0.0, 1)),
    EXT_ANISOTROPY: (("anisotropyStrength", "anisotropy_strength", 0.0, 1),
                     ("anisotropyRotation", "anisotropy_rotation", 0.0, 1)),
    EXT_IRIDESCENCE: (("iridescenceFactor", "iridescence", 0.0, 1),
                      ("iridescenceIor", "iridescence_ior", 1.3, 1),
                      ("iridescenceThicknessMinimum", "iridescence_thickness_minimum", 100.0, 1),
                      ("iridescenceThicknessMaximum", "iridescence_thickness_maximum", 400.0, 1)),
    EXT_DISPERSION: (("dispersion", "dispersion", 0.0, 1),),
    EXT_DIFFUSE_TRANSMISSION: (("diffuseTransmissionFactor", "diffuse_transmission", 0.0, 1),
                               ("diffuseTransmissionColorFactor", "diffuse_transmission_color", (1.0, 1.0, 1.0), 3)),
}
GLB_MAGIC, GLB_JSON, GLB_BIN = 0x46546C67, 0x4E4F534A, 0x004E4942


def _fail(source: str, message: str) -> AlightError:
    return AlightError(f"{source}: {message}".replace("\n", "\\n"))


# --- reading ---------------------------------------------------------------------------------

def read_gltf_json(path: str | os.PathLike) -> dict:
    """The JSON document of a .gltf or .glb file."""
    p = Path(path)
    source = str(p)
    try:
        data = p.read_bytes()
    except OSError as e:
        raise _fail(source, f"cannot read ({e.strerror or e})") from None
    if data[:4] == b"glTF":
        if len(data) < 20:
            raise _fail(source, "truncated GLB header")
        length, kind = struct.unpack("<II", data[12:20])
        if kind != GLB_JSON or 20 + length > len(data):
            raise _fail(source, "GLB without a valid JSON chunk")
        data = data[20:20 + length]
    try:
        doc = json.loads(data.decode("utf-8-sig"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as e:
        raise _fail(source, f"not valid glTF JSON ({' '.join(str(e).split())})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("asset"), dict):
        raise _fail(source, "not a glTF document (no 'asset')")
    return doc


def _numbers(value: Any, n: int, default: list[float], source: str, where: str) -> list[float]:
    if value is None:
        return list(default)
    if not isinstance(value, list) or len(value) != n or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in value):
        raise _fail(source, f"{where}: expected {n} finite numbers")
    return [float(x) for x in value]


def _number(value: Any, default: float, source: str, where: str) -> float:
    return _numbers(None if value is None else [value], 1, [default], source, where)[0]


def dielectric_f0(ior: float, specular_factor: float = 1.0,
                  specular_color: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> tuple[float, float, float]:
    """KHR_materials_specular's dielectric F0 for an ior (KHR_materials_ior)."""
    base = ((ior - 1.0) / (ior + 1.0)) ** 2
    return tuple(min(base * c, 1.0) * specular_factor for c in specular_color)  # type: ignore[return-value]


def layer_fields_from_gltf(gm: dict, source: str) -> dict[str, Any]:
    """The Material fields a glTF material's layer extensions and KHR_materials_ior give
    (only those the file has; the rest keep their defaults), unvalidated."""
    ext = gm.get("extensions") or {}
    if not isinstance(ext, dict):
        raise _fail(source, "material: extensions must be an object")
    out: dict[str, Any] = {}
    for name, params in LAYER_EXTENSIONS.items():
        e = ext.get(name)
        if e is None:
            continue
        if not isinstance(e, dict):
            raise _fail(source, f"material: {name} must be an object")
        for key, field, default, count in params:
            if key in e:
                if count == 1:
                    out[field] = _number(e[key], default, source, f"{name}.{key}")
                else:
                    out[field] = tuple(_numbers(e[key], count, list(default), source, f"{name}.{key}"))
    ior = (ext.get(EXT_IOR) or {}).get("ior")
    if ior is not None:
        ior = _number(ior, DEFAULT_IOR, source, f"{EXT_IOR}.ior")
        out["ior"] = DEFAULT_IOR if ior == 0.0 else ior   # the extension's legacy 'ior 0': no ior
    return out


def material_from_gltf(gm: dict, source: str, name: str = "material") -> Material:
    """One glTF material object (a dict from the JSON's ``materials``) as a Material."""
    if not isinstance(gm, dict):
        raise _fail(source, "material: expected a JSON object")
    pbr = gm.get("pbrMetallicRoughness") or {}
    ext = gm.get("extensions") or {}
    if not isinstance(pbr, dict) or not isinstance(ext, dict):
        raise _fail(source, "material: pbrMetallicRoughness and extensions must be objects")
    base = _numbers(pbr.get("baseColorFactor"), 4, [1, 1, 1, 1], source, "baseColorFactor")
    metallic = _number(pbr.get("metallicFactor"), 1.0, source, "metallicFactor")
    roughness = _number(pbr.get("roughnessFactor"), 1.0, source, "roughnessFactor")
    emissive = _numbers(gm.get("emissiveFactor"), 3, [0, 0, 0], source, "emissiveFactor")
    strength = _number((ext.get(EXT_EMISSIVE) or {}).get("emissiveStrength"), 1.0, source, "emissiveStrength")
    ior = _number((ext.get(EXT_IOR) or {}).get("ior"), 1.5, source, "ior")
    spec = ext.get(EXT_SPECULAR) or {}
    spec_factor = _number(spec.get("specularFactor"), 1.0, source, "specularFactor")
    spec_color = _numbers(spec.get("specularColorFactor"), 3, [1, 1, 1], source, "specularColorFactor")
    if ior == 0.0:
        ior = 1.5  # the extension's legacy 'ior 0' means no ior; F0 then stays the default
    if ior < 1.0:
        raise _fail(source, f"ior: {ior:g} is below 1")
    layers = layer_fields_from_gltf(gm, source)
    layers["ior"] = ior
    m = Material(base_color=tuple(base[:3]), metallic=metallic, roughness=roughness,  # type: ignore[arg-type]
                 specular_f0=dielectric_f0(ior, spec_factor, tuple(spec_color)),  # type: ignore[arg-type]
                 emissive=tuple(e * strength for e in emissive),  # type: ignore[arg-type]
                 name=str(gm.get("name") or name), **layers)
    return validate_material(m, source)


def import_material(path: str | os.PathLike, index: int = 0, warn_textures: bool = True) -> Material:
    """The ``index``-th material of a .gltf/.glb file (a file without one is an error): its
    factors and extensions' values. Its textures are not part of a Material: where it has any,
    one warning line names them (``warn_textures``; alight.exchange.material_files.load_material_file
    reads them as TextureMaps and says what it cannot take itself)."""
    doc = read_gltf_json(path)
    materials = doc.get("materials") or []
    if not isinstance(materials, list) or not materials:
        raise _fail(str(path), "no materials in the file")
    if not 0 <= index < len(materials):
        raise _fail(str(path), f"material {index} does not exist (the file has {len(materials)})")
    material = material_from_gltf(materials[index], str(path), name=Path(path).stem)
    textures = _texture_keys(materials[index]) if warn_textures else []
    if textures:
        from alight.errors import warn

        warn(f"{Path(path).name}: materials[{index}]: {', '.join(textures)} not taken (import_material reads "
             "factors; alight.exchange.material_files.load_material_file reads the maps too, or load the file "
             "as the mesh: --mesh, Renderer.set_mesh)")
    return material


def _texture_keys(node, prefix: str = "") -> list[str]:
    """The texture slots a glTF material object uses (baseColorTexture, KHR_materials_clearcoat
    .clearcoatTexture, ...), in the file's order."""
    out = []
    if isinstance(node, dict):
        for key, value in node.items():
            if key.endswith("Texture") and isinstance(value, dict) and "index" in value:
                out.append(prefix + key)
            elif isinstance(value, dict):
                out += _texture_keys(value, prefix if key in ("pbrMetallicRoughness", "extensions") else f"{prefix}{key}.")
    return out


# --- writing ---------------------------------------------------------------------------------

def material_to_gltf(m: Material) -> tuple[dict, list[str]]:
    """A glTF material object for ``m`` and the extensions it uses."""
    m = validate_material(m)
    gm: dict[str, Any] = {
        "name": m.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [*m.base_color, 1.0],
            "metallicFactor": m.metallic,
            "roughnessFactor": m.roughness,
        },
    }
    ext: dict[str, Any] = {}
    peak = max(m.emissive)
    if peak > 0.0:
        # emissiveFactor is limited to [0,1]: anything brighter goes through the strength.
        scale = peak if peak > 1.0 else 1.0
        gm["emissiveFactor"] = [e / scale for e in m.emissive]
        if scale != 1.0:
            ext[EXT_EMISSIVE] = {"emissiveStrength": scale}
    ior = m.ior
    f0_ior = f0_from_ior(ior)
    if f0_ior == 0.0 and max(m.specular_f0) > 0.0:
        # glTF's F0 is ((ior - 1)/(ior + 1))^2 times a factor: ior 1 reflects nothing whatever
        # the factor, so this pair has no glTF form. Refused rather than written differently.
        raise _fail(m.name, f"ior {ior:g} with specular_f0 {max(m.specular_f0):g}: glTF cannot hold both "
                            "(ior 1 reflects nothing there); give one and let the other follow")
    if ior != DEFAULT_IOR:
        ext[EXT_IOR] = {"ior": ior}
    if any(abs(c - f0_ior) > 1e-12 for c in m.specular_f0) and f0_ior > 0.0:
        ext[EXT_SPECULAR] = {"specularColorFactor": [c / f0_ior for c in m.specular_f0]}
    for name, params in LAYER_EXTENSIONS.items():
        values = {key: getattr(m, field) for key, field, default, _ in params if getattr(m, field) != default}
        if values:
            ext[name] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in values.items()}
    if ext:
        gm["extensions"] = ext
    return gm, sorted(ext)


def _document(m: Material) -> dict:
    gm, used = material_to_gltf(m)
    doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": "alight"}, "materials": [gm]}
    if used:
        doc["extensionsUsed"] = used
    return doc


def _check_out(path: str | os.PathLike, suffixes: tuple[str, ...]) -> Path:
    from alight.exchange.output import check_output_path

    return check_output_path(path, suffixes)


def export_material_gltf(m: Material, path: str | os.PathLike) -> Path:
    """A material-only glTF 2.0 asset (valid: glTF needs no mesh; validators note the unused
    material as information only)."""
    out = _check_out(path, (".gltf",))
    text = json.dumps(_document(m), indent=2) + "\n"
    _write(out, text.encode("utf-8"))
    return out


def _write(out: Path, data: bytes) -> None:
    try:
        with atomic_path(out) as tmp:
            tmp.write_bytes(data)
    except OSError as e:
        raise _fail(str(out), f"cannot write ({e.strerror or e})") from None

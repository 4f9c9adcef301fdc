"""A material file as factors and maps: the one reader and writer the front ends call.

Reading: a preset name or ``.json`` preset (factors only, the format before maps existed) or a
``.gltf``/``.glb`` file's first material with its textures as ``TextureMaps`` (a .gltf's image
files by their own paths, other images as ``FILE#images[N]``). Writing: ``.json`` (factors
only: refused when the material has maps, rather than dropping them silently) or glTF through
``alight.exchange.gltf_export``.

What alight's map model cannot hold is drawn without, with a warning line each: textures on
TEXCOORD_1, rotated or per-slot transforms, samplers other than repeat/trilinear, normal scale
or occlusion strength other than 1, and the layers' textures.
"""

from __future__ import annotations

import os
from pathlib import Path

from alight.core.material import Material
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError

GLTF_SUFFIXES = (".gltf", ".glb")
# glTF textureInfo -> alight slot.
_SLOTS = (("pbrMetallicRoughness", "baseColorTexture", "base_color"),
          ("pbrMetallicRoughness", "metallicRoughnessTexture", "metallic_roughness"),
          (None, "normalTexture", "normal"), (None, "occlusionTexture", "occlusion"),
          (None, "emissiveTexture", "emissive"))
_DEFAULT_SAMPLER = {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}
# The glTF sampler enums (the spec's names for OpenGL's values), so a warning names them.
GL_SAMPLER_NAMES = {9728: "NEAREST", 9729: "LINEAR", 9984: "NEAREST_MIPMAP_NEAREST",
                    9985: "LINEAR_MIPMAP_NEAREST", 9986: "NEAREST_MIPMAP_LINEAR", 9987: "LINEAR_MIPMAP_LINEAR",
                    33071: "CLAMP_TO_EDGE", 33648: "MIRRORED_REPEAT", 10497: "REPEAT"}


def is_gltf(path: str | os.PathLike) -> bool:
    return Path(os.fspath(path)).suffix.lower() in GLTF_SUFFIXES


# How a warning tells where a layer's textures (or a second uv set's) are used: the CLI's words
# by default; the editor and the Python API pass their own (their messages name their controls
# and methods, not flags).
MESH_HINT = "render the file with --mesh to use them"
API_MESH_HINT = "load the file with Renderer.set_mesh to use them"


def load_material_file(name_or_path: str | os.PathLike, index: int = 0,
                       mesh_hint: str = MESH_HINT) -> tuple[Material, TextureMaps, list[str]]:
    """(material, maps, warnings) of a preset name, a .json preset or a glTF file's
    ``index``-th material. Errors: one-line AlightError naming the file and element."""
    text = os.fspath(name_or_path)
    if not is_gltf(text):
        from alight.exchange.presets import load_preset

        return load_preset(text), TextureMaps(), []
    from alight.exchange.gltf_material import import_material, read_gltf_json

    material = import_material(text, index, warn_textures=False)   # (its maps are read below)
    doc = read_gltf_json(text)
    maps, warnings = _maps(doc["materials"][index], doc, text, index, mesh_hint)
    return material, maps, warnings


def _maps(gm: dict, doc: dict, source: str, index: int, mesh_hint: str = MESH_HINT) -> tuple[TextureMaps, list[str]]:
    warnings: list[str] = []
    where = f"materials[{index}]"
    maps = TextureMaps()
    transforms = set()
    images = doc.get("images") or []
    textures = doc.get("textures") or []
    samplers = doc.get("samplers") or []
    for parent, key, slot in _SLOTS:
        holder = gm.get(parent) if parent else gm
        info = (holder or {}).get(key) if isinstance(holder, dict) else None
        if not isinstance(info, dict) or not isinstance(info.get("index"), int):
            continue
        element = f"{where}.{key}"
        t = info["index"]
        if not 0 <= t < len(textures) or not isinstance(textures[t], dict):
            raise AlightError(f"{source}: {element}: textures[{t}] does not exist")
        tex = textures[t]
        ext = (info.get("extensions") or {}).get("KHR_texture_transform")
        tex_coord = (ext or {}).get("texCoord", info.get("texCoord", 0))
        if tex_coord != 0:
            warnings.append(f"{source}: {element}: texCoord {tex_coord}: alight's material maps read TEXCOORD_0 only; "
                            f"left out ({mesh_hint})")
            continue
        if isinstance(ext, dict):
            if ext.get("rotation", 0.0):
                warnings.append(f"{source}: {element}: KHR_texture_transform rotation is drawn without (scale and offset kept)")
            transforms.add((tuple(ext.get("scale", (1.0, 1.0))), tuple(ext.get("offset", (0.0, 0.0)))))
        else:
            transforms.add(((1.0, 1.0), (0.0, 0.0)))
        s = tex.get("sampler")
        if isinstance(s, int) and 0 <= s < len(samplers):
            differ = [k for k in _DEFAULT_SAMPLER if samplers[s].get(k, _DEFAULT_SAMPLER[k]) != _DEFAULT_SAMPLER[k]]
            if differ:
                # Only a material file's maps: the file's own mesh draws its samplers as given
                # (alight.render.gpu_mesh), so loading it as a mesh says nothing.
                given = ", ".join(f"{k} {_gl_name(samplers[s][k])}" for k in differ)
                drawn = ", ".join(f"{k} {_gl_name(_DEFAULT_SAMPLER[k])}" for k in differ)
                warnings.append(f"{source}: textures[{t}]: sampler {given} is drawn as {drawn} (a material's "
                                f"maps are drawn repeat, trilinear; the file loaded as the mesh draws its samplers "
                                f"as given)")
        if slot == "normal" and info.get("scale", 1.0) != 1.0:
            warnings.append(f"{source}: {element}: scale {info['scale']} is drawn as 1")
        if slot == "occlusion" and info.get("strength", 1.0) != 1.0:
            warnings.append(f"{source}: {element}: strength {info['strength']} is drawn as 1")
        i = tex.get("source")
        if not isinstance(i, int) or not 0 <= i < len(images):
            raise AlightError(f"{source}: textures[{t}]: has no image source alight reads")
        maps = maps.with_slot(slot, _image_path(images[i], i, source))
    if len(transforms) > 1:
        warnings.append(f"{source}: {where}: the textures' KHR_texture_transforms differ; the first one is drawn for all")
    if transforms:
        (su, sv), (ou, ov) = sorted(transforms)[0] if len(transforms) > 1 else next(iter(transforms))
        # glTF's offset (v down) as alight's tiling of OpenGL uvs (gltf_export's inverse).
        maps = TextureMaps(**{**{s: getattr(maps, s) for s in maps.paths()},
                              "uv_scale": (float(su), float(sv)), "uv_offset": (float(ou), float(1.0 - sv - ov))})
    ext = gm.get("extensions") or {}
    for name in ("KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_anisotropy",
                 "KHR_materials_transmission", "KHR_materials_volume", "KHR_materials_specular"):
        e = ext.get(name)
        if isinstance(e, dict) and any(k.endswith("Texture") for k in e):
            warnings.append(f"{source}: {where}: {name}'s textures are drawn without ({mesh_hint})")
    return maps, warnings


def _gl_name(value) -> str:
    return GL_SAMPLER_NAMES.get(value, repr(value))


def _image_path(image: dict, i: int, source: str) -> str:
    uri = image.get("uri") if isinstance(image, dict) else None
    if isinstance(uri, str) and not uri.startswith("data:") and ":" not in uri.split("/")[0]:
        from urllib.parse import unquote

        return str((Path(source).parent / unquote(uri)).resolve())
    return f"{source}#images[{i}]"


def save_material_file(material: Material, path: str | os.PathLike, maps: TextureMaps | None = None,
                       mesh=None, description: str = "") -> list[str]:
    """Write the material (and its maps) to ``path`` by suffix: .json (a preset: factors only),
    .gltf or .glb (``mesh`` included when given). Returns notes on conversions. Errors: one-line
    AlightError naming the file."""
    maps = maps or TextureMaps()
    if is_gltf(path):
        from alight.exchange.gltf_export import export_gltf

        return export_gltf(material, path, maps, mesh)[1]
    if maps.paths():
        raise AlightError(f"{os.fspath(path)}: a .json preset holds factors only and this material has maps; "
                          f"save it as .gltf or .glb to keep them")
    from alight.exchange.presets import save_preset

    save_preset(material, path, description)
    return []

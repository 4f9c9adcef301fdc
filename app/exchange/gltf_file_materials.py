"""A mesh file's own materials (alight.core.mesh.FileMaterial, as alight.exchange.gltf loaded
them) written back as glTF material objects, for alight.exchange.gltf_export when the view shows
them.

The factors go through ``alight.exchange.gltf_material.material_to_gltf`` (the layers'
extensions included); then what only a file's material has: baseColorFactor's alpha,
alphaMode/alphaCutoff, doubleSided, KHR_materials_unlit, KHR_materials_specular's factor (F90)
and every texture slot alight draws with its texCoord, KHR_texture_transform and sampler.
Each image goes out as the file's own PNG or JPEG bytes where alight kept them
(TextureInfo.encoded) and they still decode to the pixels drawn; else (KTX2, WebP, an image
alight changed, e.g. the diffuse transmission pair packed into one by
alight.exchange.packed_textures) as a PNG of the decoded pixels: what alight draws, 8 bits a
channel, no loss. That packed pair goes out as its one image under both keys
(diffuseTransmissionTexture reads its A, diffuseTransmissionColorTexture its RGB).
"""

from __future__ import annotations

from typing import Any, Callable

from alight.core.material import DEFAULT_IOR, Material, f0_from_ior
from alight.core.mesh import FileMaterial, Sampler, TextureInfo
from alight.exchange.gltf import LAYER_TEXTURES, SAMPLER_MAG, SAMPLER_MIN, SAMPLER_WRAP
from alight.exchange.gltf_material import EXT_SPECULAR, material_to_gltf

EXT_TRANSFORM = "KHR_texture_transform"
EXT_UNLIT = "KHR_materials_unlit"
# FileMaterial slot -> where its textureInfo goes: (extension or None for the core, key); the
# layers' from the reader's own table, so a slot the reader learns is written back too.
SLOT_KEYS: dict[str, tuple[str | None, str]] = {
    "base_color": (None, "baseColorTexture"),
    "metallic_roughness": (None, "metallicRoughnessTexture"),
    "normal": (None, "normalTexture"),
    "emissive": (None, "emissiveTexture"),
    "occlusion": (None, "occlusionTexture"),
    **LAYER_TEXTURES,
}
# The sampler's codes: the reader's tables inverted.
_WRAP = {name: code for code, name in SAMPLER_WRAP.items()}
_MAG = {name: code for code, name in SAMPLER_MAG.items()}
_MIN = {name: code for code, name in SAMPLER_MIN.items()}


def gltf_sampler(s: Sampler) -> dict:
    """The glTF sampler object for ``s`` (alight.exchange.gltf's tables, inverted)."""
    return {"magFilter": _MAG[s.mag_filter], "minFilter": _MIN[s.min_filter],
            "wrapS": _WRAP[s.wrap_s], "wrapT": _WRAP[s.wrap_t]}


def factors_material(fm: FileMaterial) -> Material:
    """The Material with ``fm``'s factors (the ior and layers as the file gave them)."""
    layers = dict(fm.layers)
    ior = layers.pop("ior", DEFAULT_IOR)
    return Material(base_color=tuple(fm.base_color), metallic=fm.metallic, roughness=fm.roughness,  # type: ignore[arg-type]
                    specular_f0=tuple(fm.specular_f0), ior=ior, emissive=tuple(fm.emissive),  # type: ignore[arg-type]
                    name=fm.name or "material", **layers)


def _specular(fm: FileMaterial, ior: float) -> dict | None:
    """KHR_materials_specular's object where the factor (F90) or a specular texture needs it
    (material_to_gltf writes the colour alone, factor 1); None: material_to_gltf's stands."""
    textured = fm.specular_texture is not None or fm.specular_color_texture is not None
    f0_ior = f0_from_ior(ior)
    if not textured and fm.specular_f90 == 1.0:
        return None
    if f0_ior <= 0.0:
        return {"specularFactor": fm.specular_f90}
    if textured:   # the texels multiply the unclamped factors (FileMaterial)
        factor, colour = fm.specular_factor, [c / f0_ior for c in fm.specular_color_f0]
    else:          # specular_f0 = min(F0(ior) * colour, 1) * factor: the colour with the factor divided out
        factor = fm.specular_f90
        colour = [c / (f0_ior * factor) if factor > 0.0 else 1.0 for c in fm.specular_f0]
    return {"specularFactor": factor, "specularColorFactor": colour}


def file_material_to_gltf(fm: FileMaterial, texture: Callable[[TextureInfo, str], int]) -> tuple[dict, list[str]]:
    """The glTF material object for ``fm`` and the extensions it uses. ``texture(info, slot)``
    adds the texture (its image and sampler) to the document and returns its index."""
    m = factors_material(fm)
    gm, used = material_to_gltf(m)
    ext: dict[str, Any] = gm.setdefault("extensions", {})
    pbr = gm["pbrMetallicRoughness"]
    pbr["baseColorFactor"][3] = float(fm.alpha)
    if fm.alpha_mode != "OPAQUE":
        gm["alphaMode"] = fm.alpha_mode
        if fm.alpha_mode == "MASK":
            gm["alphaCutoff"] = float(fm.alpha_cutoff)
    if fm.double_sided:
        gm["doubleSided"] = True
    if fm.unlit:
        ext[EXT_UNLIT] = {}
    spec = _specular(fm, m.ior)
    if spec is not None:
        ext[EXT_SPECULAR] = spec
    for slot, info in fm.textures().items():
        ti = texture_info(info, texture(info, slot))
        if slot == "normal" and fm.normal_scale != 1.0:
            ti["scale"] = float(fm.normal_scale)
        if slot == "occlusion" and fm.occlusion_strength != 1.0:
            ti["strength"] = float(fm.occlusion_strength)
        if slot == "clearcoat_normal" and fm.clearcoat_normal_scale != 1.0:
            ti["scale"] = float(fm.clearcoat_normal_scale)
        if slot == "diffuse_transmission":   # packed: A the strength, RGB the colour (module docstring)
            d = ext.setdefault("KHR_materials_diffuse_transmission", {})
            d["diffuseTransmissionTexture"] = ti
            d["diffuseTransmissionColorTexture"] = dict(ti)
            continue
        name, key = SLOT_KEYS[slot]
        if name is None:
            (pbr if slot in ("base_color", "metallic_roughness") else gm)[key] = ti
        else:
            ext.setdefault(name, {})[key] = ti
        if "extensions" in ti:
            used.append(EXT_TRANSFORM)
    used = sorted(set(used) | set(ext))
    if not ext:
        del gm["extensions"]
    return gm, used


def texture_info(info: TextureInfo, index: int) -> dict:
    """A glTF textureInfo for ``info`` (texCoord and KHR_texture_transform as loaded)."""
    ti: dict[str, Any] = {"index": index}
    if info.tex_coord:
        ti["texCoord"] = int(info.tex_coord)
    t = info.transform
    if t is not None:
        ti["extensions"] = {EXT_TRANSFORM: {"offset": [float(x) for x in t.offset], "rotation": float(t.rotation),
                                            "scale": [float(x) for x in t.scale]}}
    return ti


def count_textures(materials) -> int:
    """How many distinct images ``materials`` (FileMaterials) draw with."""
    return len({id(info.image) for fm in materials for info in fm.textures().values()})

"""Mesh files (.obj .gltf .glb .ply .stl) read with trimesh into ``alight.core.mesh.Mesh``.

trimesh is imported lazily inside the loader so that start-up and the built-in meshes never pay
for it. Every problem with a file becomes a one-line :class:`AlightError` naming the file.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any, Callable

import numpy as np

from alight.core.mesh import (
    BUILTIN_MESHES,
    FileMaterial,
    Mesh,
    MeshPart,
    _normalize,
    compute_tangents,
    cube,
    plane,
    smooth_normals,
    sphere,
)
from alight.errors import AlightError

MESH_EXTENSIONS = (".obj", ".gltf", ".glb", ".ply", ".stl")


_BUILDERS: dict[str, Callable[[], Mesh]] = {"sphere": sphere, "cube": cube, "plane": plane}


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def load_mesh(spec: str) -> Mesh:
    """A built-in mesh by name, or a mesh file flattened to world-space parts."""
    if spec in _BUILDERS:
        return _BUILDERS[spec]()
    path = Path(spec)
    ext = path.suffix.lower()
    if ext not in MESH_EXTENSIONS:
        if not ext and not path.exists():
            raise AlightError(f"{spec}: neither a built-in mesh ({', '.join(BUILTIN_MESHES)}) nor a file")
        raise AlightError(
            f"{spec}: unsupported mesh format '{ext or '(none)'}' (use {', '.join(MESH_EXTENSIONS)})"
        )
    if not path.is_file():
        raise AlightError(f"{spec}: no such file")

    import trimesh  # lazily: importing trimesh costs start-up time the built-ins do not need

    try:
        scene = trimesh.load(str(path), force="scene", process=False)
    except Exception as exc:  # trimesh raises anything from ValueError to KeyError on bad files
        raise AlightError(f"{spec}: cannot read the file ({_one_line(exc)})") from None
    try:
        extras = _gltf_material_params(path) if ext in (".gltf", ".glb") else {}
        textures: dict[int, np.ndarray] = {}
        parts = []
        for node in scene.graph.nodes_geometry:
            transform, geom_name = scene.graph[node]
            geom = scene.geometry.get(geom_name)
            if not isinstance(geom, trimesh.Trimesh) or len(geom.faces) == 0:
                continue  # point clouds and line paths have no triangles to render
            part = _part_from_trimesh(spec, str(node), geom, np.asarray(transform), textures, extras)
            if part is not None:
                parts.append(part)
    except AlightError:
        raise
    except Exception as exc:  # e.g. a texture that PIL can only decode lazily and fails on
        raise AlightError(f"{spec}: cannot read the file ({_one_line(exc)})") from None
    if not parts:
        raise AlightError(f"{spec}: no triangles in the file")
    return Mesh(parts, str(spec))


def _part_from_trimesh(spec: str, name: str, geom, transform: np.ndarray,
                       textures: dict[int, np.ndarray], extras: dict[str, dict]) -> MeshPart | None:
    """One trimesh geometry placed by its node transform; None when no face survives."""
    positions = np.asarray(geom.vertices, dtype=np.float64)
    faces = np.asarray(geom.faces, dtype=np.int64).reshape(-1, 3)
    if not np.isfinite(positions).all():
        raise AlightError(f"{spec}: vertex positions contain NaN or Inf")
    if faces.size and (faces.min() < 0 or faces.max() >= len(positions)):
        raise AlightError(f"{spec}: face indices out of range")
    if not np.isfinite(transform).all():
        raise AlightError(f"{spec}: node transform contains NaN or Inf")
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
    if len(faces) == 0:
        return None

    # The file's normals, if trimesh kept them (it stores loaded normals in its cache; reading
    # the public property would silently compute them instead, and we want to know).
    cache = getattr(getattr(geom, "_cache", None), "cache", {})
    file_normals = cache.get("vertex_normals") if isinstance(cache, dict) else None

    # To world space. Normals take the cofactor matrix (= det * inverse transpose) times
    # sign(det); a mirroring transform (det < 0) also reverses the winding to stay CCW.
    m, t = transform[:3, :3].astype(np.float64), transform[:3, 3].astype(np.float64)
    cof = np.stack([np.cross(m[1], m[2]), np.cross(m[2], m[0]), np.cross(m[0], m[1])])
    det = float(np.dot(m[0], cof[0]))
    positions = positions @ m.T + t
    if det < 0:
        faces = faces[:, ::-1]
        cof = -cof

    computed, computed_ok = _normalize(smooth_normals(positions, faces))
    normals = computed
    if file_normals is not None and np.shape(file_normals) == positions.shape:
        from_file, file_ok = _normalize(np.asarray(file_normals, dtype=np.float64) @ cof.T)
        normals = np.where(file_ok[:, None], from_file, computed)
        computed_ok = computed_ok | file_ok
    normals[~computed_ok] = (0.0, 1.0, 0.0)

    uv = getattr(geom.visual, "uv", None)
    if uv is not None and np.shape(uv) == (len(positions), 2):
        uvs = np.nan_to_num(np.asarray(uv, dtype=np.float64), nan=0.0, posinf=0.0, neginf=0.0)
    else:
        uvs = np.zeros((len(positions), 2))

    return MeshPart(
        name=name,
        positions=np.ascontiguousarray(positions, dtype=np.float32),
        normals=np.ascontiguousarray(normals, dtype=np.float32),
        uvs=np.ascontiguousarray(uvs, dtype=np.float32),
        tangents=compute_tangents(positions, normals, uvs, faces),
        indices=np.ascontiguousarray(faces, dtype=np.uint32),
        material=_file_material(getattr(geom.visual, "material", None), textures, extras),
    )


def _texture(image: Any, cache: dict[int, np.ndarray]) -> np.ndarray | None:
    """A PIL image as (H, W, 4) uint8 RGBA, row 0 = top (PIL's order); shared images converted once."""
    if image is None or not hasattr(image, "convert"):
        return None
    key = id(image)
    if key not in cache:
        cache[key] = np.ascontiguousarray(np.asarray(image.convert("RGBA"), dtype=np.uint8))
    return cache[key]


def _factor(value: Any, default: tuple[float, ...]) -> np.ndarray:
    """A colour factor as floats 0..1: trimesh stores baseColorFactor quantised to uint8 0-255."""
    if value is None:
        return np.array(default, dtype=np.float64)
    arr = np.asarray(value)
    return arr / 255.0 if arr.dtype.kind in "ui" else arr.astype(np.float64)


def _file_material(mat: Any, textures: dict[int, np.ndarray], extras: dict[str, dict]) -> FileMaterial | None:
    """The file's material in our terms; None for vertex colours or trimesh's placeholder."""
    kind = type(mat).__name__
    if kind == "PBRMaterial":
        extra = extras.get(mat.name, {}) if mat.name is not None else {}
        base = _factor(mat.baseColorFactor, (1.0, 1.0, 1.0, 1.0))
        if "base_color_factor" in extra:  # exact linear factor rather than trimesh's uint8
            base = np.asarray(extra["base_color_factor"], dtype=np.float64)
        emissive = _factor(mat.emissiveFactor, (0.0, 0.0, 0.0))[:3] * extra.get("emissive_strength", 1.0)
        return FileMaterial(
            base_color=tuple(float(x) for x in base[:3]),
            metallic=float(1.0 if mat.metallicFactor is None else mat.metallicFactor),
            roughness=float(1.0 if mat.roughnessFactor is None else mat.roughnessFactor),
            emissive=tuple(float(x) for x in emissive),
            alpha=float(base[3]) if len(base) > 3 else 1.0,
            base_color_texture=_texture(mat.baseColorTexture, textures),
            metallic_roughness_texture=_texture(mat.metallicRoughnessTexture, textures),
            normal_texture=_texture(mat.normalTexture, textures),
            normal_scale=float(extra.get("normal_scale", 1.0)),
            emissive_texture=_texture(mat.emissiveTexture, textures),
            occlusion_texture=_texture(mat.occlusionTexture, textures),
            occlusion_strength=float(extra.get("occlusion_strength", 1.0)),
            layers=dict(extra.get("layers", {})),
            **extra.get("layer_textures", {}),
        )
    if kind == "SimpleMaterial":
        if getattr(mat, "_name", None) is None:
            # trimesh's placeholder (a grey 2x2 image) for an OBJ with uvs but no usable .mtl
            return None
        diffuse = _factor(mat.diffuse, (1.0, 1.0, 1.0, 1.0))
        return FileMaterial(
            # MTL Kd is display-referred in practice; (x/255)**2.2 approximates the sRGB decode.
            base_color=tuple(float(x) ** 2.2 for x in diffuse[:3]),
            metallic=0.0,
            roughness=0.5,
            emissive=(0.0, 0.0, 0.0),
            alpha=float(diffuse[3]) if len(diffuse) > 3 else 1.0,
            base_color_texture=_texture(mat.image, textures),
            metallic_roughness_texture=None,
            normal_texture=None,
            normal_scale=1.0,
            emissive_texture=None,
            occlusion_texture=None,
            occlusion_strength=1.0,
        )
    return None


def _layer_fields(gm: dict, source: str) -> dict[str, Any]:
    """The ior and layer factors of one glTF material (alight.exchange.gltf_material), checked
    against the model's ranges; a bad value is a one-line error naming the file."""
    from alight.core.material import LAYER_FIELDS, Material, validate_material
    from alight.exchange.gltf_material import EXT_IOR, EXT_SPECULAR, layer_fields_from_gltf, material_from_gltf

    fields = layer_fields_from_gltf(gm, source)
    ext = gm.get("extensions") or {}
    if EXT_IOR in ext or EXT_SPECULAR in ext:   # the file's dielectric: ior and F0 together
        m = material_from_gltf({"extensions": {k: ext[k] for k in (EXT_IOR, EXT_SPECULAR) if k in ext}}, source)
        fields["ior"], fields["specular_f0"] = m.ior, m.specular_f0
    if fields:
        m = validate_material(Material(**fields), f"{source}: material '{gm.get('name')}'")
        fields = {f: getattr(m, f) for f in fields if f in LAYER_FIELDS or f in ("ior", "specular_f0")}
    return fields


def _gltf_material_params(path: Path) -> dict[str, dict]:
    """Material values trimesh drops, read from the glTF JSON, keyed by (unique) material name.

    trimesh keeps neither normalTexture.scale, occlusionTexture.strength nor
    KHR_materials_emissive_strength, and it quantises baseColorFactor to uint8. Materials are
    matched to trimesh's by name, so nameless or duplicate-named ones keep the defaults.
    Any problem here just means defaults: trimesh has already validated the file.
    """
    try:
        data = path.read_bytes()
        binary = None
        if data[:4] == b"glTF":
            length, kind = struct.unpack("<II", data[12:20])
            if kind != 0x4E4F534A:  # 'JSON'
                return {}
            doc = json.loads(data[20:20 + length])
            rest = 20 + length
            if len(data) >= rest + 8:
                bin_length, bin_kind = struct.unpack("<II", data[rest:rest + 8])
                if bin_kind == 0x004E4942:  # 'BIN\0'
                    binary = data[rest + 8:rest + 8 + bin_length]
        else:
            doc = json.loads(data)
        materials = doc.get("materials", [])
        names = [m.get("name") for m in materials]
        out: dict[str, dict] = {}
        for m in materials:
            name = m.get("name")
            if name is None or names.count(name) != 1:
                continue
            params: dict[str, Any] = {}
            bcf = m.get("pbrMetallicRoughness", {}).get("baseColorFactor")
            if isinstance(bcf, list) and len(bcf) == 4:
                params["base_color_factor"] = [float(x) for x in bcf]
            if "scale" in m.get("normalTexture", {}):
                params["normal_scale"] = float(m["normalTexture"]["scale"])
            if "strength" in m.get("occlusionTexture", {}):
                params["occlusion_strength"] = float(m["occlusionTexture"]["strength"])
            strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {})
            if "emissiveStrength" in strength:
                params["emissive_strength"] = float(strength["emissiveStrength"])
            params["layers"] = _layer_fields(m, str(path))
            params["layer_textures"] = _layer_textures(doc, binary, path.parent, m)
            out[name] = params
        return out
    except AlightError:
        raise
    except Exception:
        return {}


# The layers' textures alight draws (FileMaterial fields): (extension, textureInfo key).
LAYER_TEXTURES = {
    "clearcoat_texture": ("KHR_materials_clearcoat", "clearcoatTexture"),
    "clearcoat_roughness_texture": ("KHR_materials_clearcoat", "clearcoatRoughnessTexture"),
    "clearcoat_normal_texture": ("KHR_materials_clearcoat", "clearcoatNormalTexture"),
    "sheen_color_texture": ("KHR_materials_sheen", "sheenColorTexture"),
    "sheen_roughness_texture": ("KHR_materials_sheen", "sheenRoughnessTexture"),
}


def _layer_textures(doc: dict, binary: bytes | None, folder: Path, gm: dict) -> dict[str, Any]:
    """FileMaterial fields for the layer textures a glTF material names (images decoded), and
    the coat normal map's scale. They are read with TEXCOORD_0, as the core maps are here."""
    out: dict[str, Any] = {}
    ext = gm.get("extensions") or {}
    for slot, (name, key) in LAYER_TEXTURES.items():
        info = (ext.get(name) or {}).get(key)
        if isinstance(info, dict) and "index" in info:
            image = _gltf_texture_image(doc, binary, folder, info["index"])
            if image is not None:
                out[slot] = image
                if slot == "clearcoat_normal_texture":
                    out["clearcoat_normal_scale"] = float(info.get("scale", 1.0))
    return out


def _gltf_texture_image(doc: dict, binary: bytes | None, folder: Path, index: int) -> np.ndarray | None:
    """glTF texture ``index``'s image as (H, W, 4) uint8 RGBA (row 0 = top), decoded with Pillow
    from its bufferView (a .glb's binary chunk or a buffer's file) or its own file; None when it
    does not resolve (trimesh reads the core textures, not the extensions')."""
    import base64
    import io

    from PIL import Image

    image = doc["images"][int(doc["textures"][int(index)]["source"])]
    if "bufferView" in image:
        view = doc["bufferViews"][int(image["bufferView"])]
        uri = doc["buffers"][int(view.get("buffer", 0))].get("uri")
        if uri is None:
            blob = binary
        elif uri.startswith("data:"):
            blob = base64.b64decode(uri.split(",", 1)[1])
        else:
            blob = (folder / uri).read_bytes()
        if blob is None:
            return None
        start = int(view.get("byteOffset", 0))
        encoded = blob[start:start + int(view["byteLength"])]
    elif str(image.get("uri", "")).startswith("data:"):
        encoded = base64.b64decode(image["uri"].split(",", 1)[1])
    else:
        encoded = (folder / image["uri"]).read_bytes()
    with Image.open(io.BytesIO(encoded)) as im:
        return np.ascontiguousarray(np.asarray(im.convert("RGBA"), dtype=np.uint8))

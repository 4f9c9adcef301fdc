"""glTF 2.0 (.gltf, .glb) into ``alight.core.mesh.Mesh``: the standard library's json parses the
document, numpy decodes the accessors (``alight.exchange.gltf_accessors``), Pillow the images,
and ``alight.core.mikktspace`` makes the tangents a file leaves out. (pygltflib was measured and
left out: its dataclasses-json parse of MetalRoughSpheresNoTextures' 625 objects took about 2 s
where json.loads takes milliseconds, and it decodes no accessor; see docs/guides/files.md, "Which library does what, and why".)

What the specification's MUSTs ask of a viewer is done here (section numbers of glTF 2.0):
the default scene's node hierarchy with TRS or matrix transforms (3.5), a mirroring transform
reversing the winding (3.7.4), primitive modes TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN
(3.7.2.1; points and lines are skipped with one warning), flat normals where NORMAL is missing
(supplied tangents then ignored), MikkTSpace tangents where TANGENT is missing under a normal
map, COLOR_0, TEXCOORD_0/1, every material slot's texCoord, samplers, alphaMode and
alphaCutoff, doubleSided, cameras (3.10) and the extensions in ``SUPPORTED``. An extension in
``extensionsRequired`` that alight does not support refuses the file; one that is only used is
rendered without, with one warning line per extension.
"""

from __future__ import annotations

import json
import math
import os
import struct
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from alight.core.mesh import (
    FileMaterial,
    Mesh,
    MeshPart,
    Sampler,
    TextureInfo,
    TextureTransform,
    _normalize,
    cross_rows,
    far_origin,
    rows_times,
)
from alight.core.scene import Camera, Light
from alight.errors import AlightError
from alight.exchange.gltf_accessors import Accessors, fail, meshopt_available, read_uri
from alight.exchange.packed_textures import pack_diffuse_transmission

# Extensions alight renders as their specifications say.
SUPPORTED = {
    "KHR_texture_transform", "KHR_materials_unlit", "KHR_materials_emissive_strength", "KHR_materials_ior",
    "KHR_materials_specular", "KHR_mesh_quantization", "KHR_lights_punctual", "EXT_texture_webp",
    "KHR_draco_mesh_compression",
    "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_anisotropy", "KHR_materials_transmission",
    "KHR_materials_volume", "KHR_materials_iridescence", "KHR_materials_dispersion",
    "KHR_materials_diffuse_transmission",
    "EXT_mesh_gpu_instancing",   # each instance drawn as a copy of its node's mesh (_Reader._instances)
    "KHR_materials_variants",    # every material a variant picks is read; none active unless chosen (select_variant)
    "KHR_node_visibility",       # a node with visible false hides its meshes and lights and its descendants'
}
# Metadata: what these hold changes no pixel, so a file using (or requiring) one is drawn as
# without it and nothing is said. Each specification's own words:
METADATA = {
    # XMP packets (title, author, licence) on the asset, scenes, nodes, meshes, materials: "Metadata
    # has no normative effect on the glTF asset appearance and rendering" (Blender writes it).
    "KHR_xmp_json_ld",
    "KHR_xmp",                  # its archived predecessor, the same sentence
    "FB_geometry_metadata",     # a scene's vertex and primitive counts and bounds, for choosing a scene
    "AGI_stk_metadata",         # STK's solar panel groups and sensor no-obscuration flags
    "EXT_structural_metadata",  # schemas and property tables of features (3D Tiles); read by no shader
    "EXT_mesh_features",        # feature IDs per vertex, texel or instance, which index that metadata
}
SUPPORTED |= METADATA
# The layers' textures alight draws: FileMaterial slot -> (extension, textureInfo key).
LAYER_TEXTURES = {
    "clearcoat": ("KHR_materials_clearcoat", "clearcoatTexture"),
    "clearcoat_roughness": ("KHR_materials_clearcoat", "clearcoatRoughnessTexture"),
    "clearcoat_normal": ("KHR_materials_clearcoat", "clearcoatNormalTexture"),
    "sheen_color": ("KHR_materials_sheen", "sheenColorTexture"),
    "sheen_roughness": ("KHR_materials_sheen", "sheenRoughnessTexture"),
    "anisotropy": ("KHR_materials_anisotropy", "anisotropyTexture"),
    "transmission": ("KHR_materials_transmission", "transmissionTexture"),
    "thickness": ("KHR_materials_volume", "thicknessTexture"),
    "iridescence": ("KHR_materials_iridescence", "iridescenceTexture"),
    "iridescence_thickness": ("KHR_materials_iridescence", "iridescenceThicknessTexture"),
    "diffuse_transmission": ("KHR_materials_diffuse_transmission", "diffuseTransmissionTexture"),
    "diffuse_transmission_color": ("KHR_materials_diffuse_transmission", "diffuseTransmissionColorTexture"),
    "specular": ("KHR_materials_specular", "specularTexture"),
    "specular_color": ("KHR_materials_specular", "specularColorTexture"),
}
# EXT_mesh_gpu_instancing: about this many vertices' copies are transformed in one batch.
INSTANCE_BATCH_VERTICES = 1 << 15
# Compression a file cannot be read without: refused in one line when no library decodes it.
COMPRESSION = {"KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression", "KHR_texture_basisu"}

PNG_MAGIC, JPEG_MAGIC = b"\x89PNG\r\n\x1a\n", b"\xff\xd8\xff"
# glTF sampler codes -> alight.core.mesh.Sampler's names (gltf_file_materials inverts them).
SAMPLER_WRAP = {10497: "repeat", 33071: "clamp_to_edge", 33648: "mirrored_repeat"}
SAMPLER_MAG = {9728: "nearest", 9729: "linear"}
SAMPLER_MIN = {9728: "nearest", 9729: "linear", 9984: "nearest_mipmap_nearest", 9985: "linear_mipmap_nearest",
               9986: "nearest_mipmap_linear", 9987: "linear_mipmap_linear"}
_SRGB_SLOTS = ("base_color", "emissive")
_MODE_NAMES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP"}


# The vertex attributes read: skins need the joints and weights, the rest is drawn.
_ATTRIBUTES = ("POSITION", "NORMAL", "TANGENT", "TEXCOORD_0", "TEXCOORD_1", "COLOR_0",
               "JOINTS_0", "WEIGHTS_0", "JOINTS_1", "WEIGHTS_1")


def draco_values(values: np.ndarray, accessor, normalize: bool = True) -> np.ndarray:
    """A Draco-decoded attribute (N, k) as its accessor says: the values cast to the accessor's
    componentType, then float32 (dequantized when ``normalized``) unless ``normalize`` is False.
    DracoPy hands quantized attributes back as float32 or uint32 holding the integers."""
    from alight.exchange.gltf_accessors import COMPONENT_TYPES, dequantize

    dtype = COMPONENT_TYPES.get(accessor.componentType, np.float32)
    if dtype is np.float32:
        return np.asarray(values, np.float32)
    typed = np.rint(np.asarray(values, np.float64)).astype(dtype) if values.dtype.kind == "f" else values.astype(dtype)
    if not normalize:
        return typed
    return dequantize(typed) if accessor.normalized else typed.astype(np.float32)


def _has_plain_data(doc, attrs) -> bool:
    """Whether a primitive's POSITION accessor holds data of its own (Draco's fallback)."""
    index = getattr(attrs, "POSITION", None)
    accessors = doc.accessors or []
    return index is not None and 0 <= int(index) < len(accessors) and (
        accessors[int(index)].bufferView is not None or accessors[int(index)].sparse is not None)


def _skin_attributes(arrays: dict, kind: str, origin: np.ndarray) -> tuple[np.ndarray, ...]:
    """JOINTS_n or WEIGHTS_n (n = 0, 1, ... while present), each (N, 4), in the decoded vertex order."""
    out = []
    while f"{kind}_{len(out)}" in arrays:
        out.append(np.asarray(arrays[f"{kind}_{len(out)}"])[origin])
    return tuple(out)


KTX2_MAGIC = b"\xabKTX 20\xbb\r\n\x1a\n"


def _ktx2_available() -> bool:
    try:
        import alktx2  # noqa: F401
    except ImportError:
        return False
    return True


def decode_image(data: bytes, where: str) -> np.ndarray:
    """A glTF image's bytes as (H, W, 4) uint8 RGBA, row 0 = top: KTX2 (KHR_texture_basisu's
    Basis Universal ETC1S or UASTC) transcoded to RGBA8 by alktx2 (Basis Universal's own
    transcoder), everything else decoded by Pillow (``alight.exchange.images.decode_texture``).
    The top mip level is taken; alight builds its own mip chain as for any image."""
    from alight.exchange.images import decode_texture

    if data[:12] == KTX2_MAGIC:
        if not _ktx2_available():
            raise AlightError(f"{where}: a KTX2 image and alktx2 (its transcoder) is not installed")
        import alktx2

        try:
            # TGA: an uncompressed container Pillow reads, so nothing is spent compressing.
            data, _ = alktx2.decode_ktx2_to_bytes(bytes(data), format="tga")
        except Exception as exc:   # the binding raises RuntimeError or ValueError
            raise AlightError(f"{where}: cannot transcode the KTX2 image ({_one_line(exc)})") from None
    return decode_texture(data, where)


def _draco_available() -> bool:
    try:
        import DracoPy  # noqa: F401
    except ImportError:
        return False
    return True


@dataclass
class _Local:
    """One primitive decoded in its mesh's own space (shared by every node that instances it)."""

    positions: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    uvs1: np.ndarray | None
    colors: np.ndarray | None
    tangents: np.ndarray | None   # None: made later from the world-space part (MeshPart.tangents)
    indices: np.ndarray
    material: FileMaterial | None
    joints: tuple[np.ndarray, ...] = ()    # JOINTS_n (N, 4) ints, with WEIGHTS_n, for a skin
    weights: tuple[np.ndarray, ...] = ()


class _Json(dict):
    """A JSON object whose glTF properties read as attributes (``node.mesh``; None when absent).
    ``sparse.values`` is the one name a dict method shadows: read it as ``sparse["values"]``."""

    def __getattr__(self, name: str):
        return self.get(name)


def read_document(path: Path, spec: str) -> tuple[_Json, bytes | None]:
    """The JSON document of a .gltf or .glb (section 4, "GLB File Format Specification") and the
    GLB binary chunk (None for .gltf)."""
    data = path.read_bytes()
    blob = None
    if data[:4] == b"glTF":
        if len(data) < 20:
            raise AlightError(f"{spec}: cannot read the file (truncated GLB header)")
        version, total = struct.unpack_from("<II", data, 4)
        if version != 2:
            raise AlightError(f"{spec}: GLB container version {version}: only 2 is supported")
        if total > len(data):
            raise AlightError(f"{spec}: cannot read the file (truncated: the GLB header says {total} bytes, "
                              f"the file has {len(data)})")
        chunks, offset = {}, 12
        while offset + 8 <= total:
            length, kind = struct.unpack_from("<II", data, offset)
            if offset + 8 + length > total:
                raise AlightError(f"{spec}: cannot read the file (a GLB chunk runs past the end)")
            chunks.setdefault(kind, data[offset + 8:offset + 8 + length])
            offset += 8 + length + (-length % 4 if kind != 0x4E4F534A else 0)
        if 0x4E4F534A not in chunks:
            raise AlightError(f"{spec}: cannot read the file (no JSON chunk in the GLB)")
        text, blob = chunks[0x4E4F534A], chunks.get(0x004E4942)
    else:
        text = data
    try:
        doc = json.loads(text.decode("utf-8-sig"), object_hook=_Json)
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise AlightError(f"{spec}: cannot read the file (not valid glTF JSON: {_one_line(exc)})") from None
    if not isinstance(doc, _Json) or not isinstance(doc.asset, dict):
        raise AlightError(f"{spec}: cannot read the file (not a glTF document: no 'asset')")
    return doc, blob


class _Reader:
    def __init__(self, path: Path, spec: str):
        self.source = spec
        doc, blob = read_document(path, spec)
        version = str(doc.asset.get("version") or "")
        if not version.startswith("2."):
            raise AlightError(f"{spec}: asset.version {version or '(none)'}: only glTF 2.x is supported")
        self.doc = doc
        self.acc = Accessors(doc, spec, path.parent, blob)
        self.base = path.parent
        self.warnings: list[str] = []
        self._warned: set[str] = set()
        self._images: dict[int, np.ndarray] = {}
        self._encoded: dict[int, bytes] = {}   # the PNG and JPEG images' bytes (TextureInfo.encoded)
        self._materials: dict[int, FileMaterial] = {}
        self._locals: dict[tuple, _Local | None] = {}
        self._check_extensions()
        self.variants = _variant_names(doc, spec)

    # --- messages ------------------------------------------------------------------------

    def warn(self, key: str, line: str) -> None:
        if key not in self._warned:
            self._warned.add(key)
            self.warnings.append(f"{self.source}: {line}")

    def _check_extensions(self) -> None:
        used = list(self.doc.extensionsUsed or [])
        required = list(self.doc.extensionsRequired or [])
        supported = set(SUPPORTED)
        if not _draco_available():
            supported.discard("KHR_draco_mesh_compression")
        if meshopt_available():
            supported.update(("EXT_meshopt_compression", "KHR_meshopt_compression"))
        if _ktx2_available():
            supported.add("KHR_texture_basisu")
        for name in required:
            if name not in supported:
                why = ("no library that decodes it installs here" if name in COMPRESSION
                       else "alight does not support it")
                raise fail(self.source, "extensionsRequired", f"{name} is required and {why}")
        for name in used:
            if name not in supported:
                self.warn(f"ext:{name}", f"extensionsUsed: {name} is not supported; rendered without it")

    # --- images, textures, materials ------------------------------------------------------

    def _image_bytes(self, index: int) -> bytes:
        images = self.doc.images or []
        where = f"images[{index}]"
        if not 0 <= index < len(images):
            raise fail(self.source, where, "does not exist")
        image = images[index]
        if image.uri is not None:
            missing = _missing_image_file(self.base, image.uri)
            if missing is not None:   # as viewers do: drawn without it, said once
                self.warn(f"missing-image:{index}", f"{where}: '{image.uri}' not found ({missing}); the "
                                                    f"materials that use it are drawn without this texture")
                return None
            return read_uri(self.source, self.base, image.uri, where)
        if image.bufferView is not None:
            data, start, length, _ = self.acc.view_bytes(image.bufferView)
            return data[start:start + length]
        raise fail(self.source, where, "has neither uri nor bufferView")

    def _decode_images(self, indices: list[int]) -> None:
        """Decode the images materials use, two at a time (Pillow releases the GIL while decoding)."""
        todo = [i for i in dict.fromkeys(indices) if i not in self._images]
        if not todo:
            return
        blobs = [self._image_bytes(i) for i in todo]
        for i in [i for i, blob in zip(todo, blobs) if blob is None]:   # a missing file: no texture
            self._images[i] = None
        todo, blobs = [i for i, b in zip(todo, blobs) if b is not None], [b for b in blobs if b is not None]
        for i, blob in zip(todo, blobs):
            if bytes(blob[:8]) == PNG_MAGIC or bytes(blob[:3]) == JPEG_MAGIC:
                self._encoded[i] = bytes(blob)
        if not todo:
            return
        wheres = [f"{self.source}: images[{i}]" for i in todo]
        if len(todo) == 1:
            self._images[todo[0]] = decode_image(blobs[0], wheres[0])
            return
        with ThreadPoolExecutor(max_workers=min(len(todo), os.cpu_count() or 2)) as pool:
            for i, image in zip(todo, pool.map(decode_image, blobs, wheres)):
                self._images[i] = image

    def _texture_source(self, index: int, element: str) -> int:
        textures = self.doc.textures or []
        if not 0 <= index < len(textures):
            raise fail(self.source, element, f"textures[{index}] does not exist")
        tex = textures[index]
        ext = tex.extensions or {}
        source = tex.source
        webp = ext.get("EXT_texture_webp")
        if isinstance(webp, dict) and webp.get("source") is not None:
            source = webp["source"]
        basisu = ext.get("KHR_texture_basisu")
        if isinstance(basisu, dict) and basisu.get("source") is not None:
            if _ktx2_available():
                source = basisu["source"]
            elif tex.source is None:
                raise fail(self.source, f"textures[{index}]", "KHR_texture_basisu: no library that decodes it installs here")
        if source is None:
            raise fail(self.source, f"textures[{index}]", "has no image source alight can decode")
        return int(source)

    def _sampler(self, texture_index: int) -> Sampler:
        tex = self.doc.textures[texture_index]
        if tex.sampler is None:
            return Sampler()
        samplers = self.doc.samplers or []
        if not 0 <= tex.sampler < len(samplers):
            raise fail(self.source, f"textures[{texture_index}]", f"samplers[{tex.sampler}] does not exist")
        s = samplers[tex.sampler]
        where = f"samplers[{tex.sampler}]"
        for name, value, table in (("wrapS", s.wrapS, SAMPLER_WRAP), ("wrapT", s.wrapT, SAMPLER_WRAP)):
            if value is not None and value not in table:
                raise fail(self.source, where, f"{name} {value} is not a glTF wrap mode")
        return Sampler(wrap_s=SAMPLER_WRAP.get(s.wrapS if s.wrapS is not None else 10497, "repeat"),
                       wrap_t=SAMPLER_WRAP.get(s.wrapT if s.wrapT is not None else 10497, "repeat"),
                       mag_filter=SAMPLER_MAG.get(s.magFilter, "linear"),
                       min_filter=SAMPLER_MIN.get(s.minFilter, "linear_mipmap_linear"))

    def _texture_info(self, info, element: str) -> tuple[TextureInfo, int] | None:
        """A material's textureInfo: (TextureInfo without its image yet, image index)."""
        if info is None or info.index is None:
            return None
        tex_coord = int(info.texCoord or 0)
        transform = None
        ext = (info.extensions or {}).get("KHR_texture_transform")
        if isinstance(ext, dict):
            try:
                offset = tuple(float(x) for x in ext.get("offset", (0.0, 0.0)))
                scale = tuple(float(x) for x in ext.get("scale", (1.0, 1.0)))
                rotation = float(ext.get("rotation", 0.0))
            except (TypeError, ValueError):
                raise fail(self.source, f"{element}.extensions.KHR_texture_transform", "bad offset, rotation or scale") from None
            if len(offset) != 2 or len(scale) != 2 or not all(map(math.isfinite, (*offset, *scale, rotation))):
                raise fail(self.source, f"{element}.extensions.KHR_texture_transform", "bad offset, rotation or scale")
            transform = TextureTransform(offset, rotation, scale)  # type: ignore[arg-type]
            if ext.get("texCoord") is not None:
                tex_coord = int(ext["texCoord"])
        if tex_coord not in (0, 1):
            self.warn(f"texcoord:{tex_coord}", f"{element}: texCoord {tex_coord}: only TEXCOORD_0 and TEXCOORD_1 "
                                               f"are read; the texture is left out")
            return None
        image_index = self._texture_source(int(info.index), element)
        return TextureInfo(image=None, tex_coord=tex_coord, transform=transform,  # type: ignore[arg-type]
                           sampler=self._sampler(int(info.index))), image_index

    def material(self, index: int) -> FileMaterial:
        fm = self._materials.get(index)
        if fm is not None:
            return fm
        from alight.exchange.gltf_material import layer_fields_from_gltf, material_from_gltf

        materials = self.doc.materials or []
        where = f"materials[{index}]"
        if not 0 <= index < len(materials):
            raise fail(self.source, where, "does not exist")
        m = materials[index]
        pbr = m.pbrMetallicRoughness
        ext = m.extensions or {}
        raw = {
            "name": m.name,
            "pbrMetallicRoughness": {} if pbr is None else {
                k: v for k, v in (("baseColorFactor", pbr.baseColorFactor), ("metallicFactor", pbr.metallicFactor),
                                  ("roughnessFactor", pbr.roughnessFactor)) if v is not None},
            "emissiveFactor": m.emissiveFactor,
            "extensions": ext,
        }
        try:
            factors = material_from_gltf(raw, self.source, name=f"material{index}")
        except AlightError as e:
            message = str(e)
            prefix = f"{self.source}: "
            raise AlightError(f"{self.source}: {where}: {message[len(prefix):] if message.startswith(prefix) else message}") from None
        base = list(pbr.baseColorFactor) if pbr is not None and pbr.baseColorFactor else [1.0, 1.0, 1.0, 1.0]
        alpha_mode = m.alphaMode or "OPAQUE"
        if alpha_mode not in ("OPAQUE", "MASK", "BLEND"):
            raise fail(self.source, where, f"alphaMode {alpha_mode!r} is not OPAQUE, MASK or BLEND")
        slots = {
            "base_color": pbr.baseColorTexture if pbr is not None else None,
            "metallic_roughness": pbr.metallicRoughnessTexture if pbr is not None else None,
            "normal": m.normalTexture, "emissive": m.emissiveTexture, "occlusion": m.occlusionTexture,
        }
        infos = {}
        for slot, (name, key) in LAYER_TEXTURES.items():
            layer_info = (ext.get(name) or {}).get(key) if isinstance(ext.get(name), dict) else None
            if isinstance(layer_info, dict):
                slots[slot] = SimpleNamespace(index=layer_info.get("index"), texCoord=layer_info.get("texCoord"),
                                              extensions=layer_info.get("extensions"))
        for slot, info in slots.items():
            got = self._texture_info(info, f"{where}.{_json_slot(slot)}")
            if got is not None:
                infos[slot] = got
        specular = {}
        spec_ext = ext.get("KHR_materials_specular")
        if isinstance(spec_ext, dict):
            # F90 = specularFactor (its texture's A multiplies it in the shader, as for F0)
            specular["specular_f90"] = float(spec_ext.get("specularFactor", 1.0))
        if "specular" in infos or "specular_color" in infos:
            # the texels multiply the factors before the extension's min(..., 1) (FileMaterial)
            spec = ext.get("KHR_materials_specular") or {}
            ior = float(factors.ior) if factors.ior is not None else 1.5
            f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
            color = spec.get("specularColorFactor") or [1.0, 1.0, 1.0]
            specular.update(specular_factor=float(spec.get("specularFactor", 1.0)),
                            specular_color_f0=tuple(f0 * float(c) for c in color))
        self._decode_images([image_index for _, image_index in infos.values()])
        textures = {}
        for slot, (info, image_index) in infos.items():
            if self._images[image_index] is None:   # its file is missing (warned)
                continue
            info.image = self._images[image_index]
            info.encoded = self._encoded.get(image_index)
            textures[f"{slot}_texture"] = info
        if "diffuse_transmission_color_texture" in textures or "diffuse_transmission_texture" in textures:
            # one texture holds both (alight.exchange.packed_textures)
            packed, note = pack_diffuse_transmission(textures.pop("diffuse_transmission_texture", None),
                                                     textures.pop("diffuse_transmission_color_texture", None))
            textures["diffuse_transmission_texture"] = packed
            if note:
                self.warn(f"packed:{index}", f"{where}.{_json_slot('diffuse_transmission')}: {note}")
        fm = FileMaterial(
            base_color=tuple(float(x) for x in factors.base_color),  # type: ignore[arg-type]
            metallic=float(factors.metallic), roughness=float(factors.roughness),
            emissive=tuple(float(x) for x in factors.emissive),  # type: ignore[arg-type]
            alpha=float(base[3]) if len(base) > 3 else 1.0,
            normal_scale=float(m.normalTexture.scale if m.normalTexture is not None and m.normalTexture.scale is not None else 1.0),
            occlusion_strength=float(m.occlusionTexture.strength if m.occlusionTexture is not None
                                     and m.occlusionTexture.strength is not None else 1.0),
            alpha_mode=alpha_mode,
            alpha_cutoff=float(0.5 if m.alphaCutoff is None else m.alphaCutoff),
            double_sided=bool(m.doubleSided),
            unlit="KHR_materials_unlit" in ext,
            specular_f0=tuple(float(x) for x in factors.specular_f0),  # type: ignore[arg-type]
            name=m.name or f"material{index}",
            layers=layer_fields_from_gltf(raw, self.source),
            clearcoat_normal_scale=float((ext.get("KHR_materials_clearcoat") or {}).get("clearcoatNormalTexture", {})
                                         .get("scale", 1.0)) if isinstance(ext.get("KHR_materials_clearcoat"), dict) else 1.0,
            **specular,
            **textures,
        )
        self._materials[index] = fm
        return fm

    def variant_materials(self, mesh_index: int, prim_index: int) -> dict[int, FileMaterial]:
        """KHR_materials_variants: {variant index: material} of a primitive's mappings (every
        material a variant can pick is read here, used or not without a variant)."""
        prim = self.doc.meshes[mesh_index].primitives[prim_index]
        ext = (prim.extensions or {}).get("KHR_materials_variants")
        if ext is None:
            return {}
        where = f"meshes[{mesh_index}].primitives[{prim_index}].extensions.KHR_materials_variants"
        mappings = ext.get("mappings") if isinstance(ext, dict) else None
        if not isinstance(mappings, list):
            raise fail(self.source, where, "mappings must be a list")
        out: dict[int, FileMaterial] = {}
        for k, mapping in enumerate(mappings):
            at = f"{where}.mappings[{k}]"
            if not isinstance(mapping, dict) or not isinstance(mapping.get("material"), int) \
                    or not isinstance(mapping.get("variants"), list):
                raise fail(self.source, at, "needs a material index and a list of variant indices")
            for v in mapping["variants"]:
                if not isinstance(v, int) or not 0 <= v < len(self.variants):
                    raise fail(self.source, at, f"variant {v!r} does not exist (the file has "
                                                f"{len(self.variants)} variants)")
                if v in out:
                    raise fail(self.source, at, f"variant {v} ({self.variants[v]!r}) is mapped twice")
                out[v] = self.material(mapping["material"])
        return out

    # --- geometry --------------------------------------------------------------------------

    def primitive(self, mesh_index: int, prim_index: int, weights: tuple[float, ...] = ()) -> _Local | None:
        """A primitive in its mesh's space with its morph targets applied at ``weights``."""
        key = (mesh_index, prim_index, weights)
        if key not in self._locals:
            self._locals[key] = self._decode_primitive(mesh_index, prim_index, weights)
        return self._locals[key]

    def _decode_primitive(self, mesh_index: int, prim_index: int, weights: tuple[float, ...] = ()) -> _Local | None:
        element = f"meshes[{mesh_index}].primitives[{prim_index}]"
        prim = self.doc.meshes[mesh_index].primitives[prim_index]
        mode = 4 if prim.mode is None else int(prim.mode)
        if mode in _MODE_NAMES:
            self.warn(f"mode:{mode}", f"{element}: mode {_MODE_NAMES[mode]}: points and lines are not drawn")
            return None
        if mode not in (4, 5, 6):
            raise fail(self.source, element, f"mode {mode} is not a glTF primitive mode")
        attrs = prim.attributes
        ext = prim.extensions or {}
        draco = ext.get("KHR_draco_mesh_compression")
        arrays = None
        if isinstance(draco, dict) and _draco_available():
            try:
                arrays, indices = self._draco(draco, prim, element)
            except AlightError as exc:
                # The extension's fallback: a file that does not require Draco also holds the
                # plain accessors, which a viewer without Draco (or with a failing one) draws.
                if "KHR_draco_mesh_compression" in (self.doc.extensionsRequired or []) or not _has_plain_data(self.doc, attrs):
                    raise
                self.warn("draco-fallback", f"{str(exc)[len(self.source) + 2:]}; the uncompressed accessors are drawn")
        if arrays is None:
            if getattr(attrs, "POSITION", None) is None:
                raise fail(self.source, element, "has no POSITION attribute")
            arrays = {}
            for name in _ATTRIBUTES:
                index = getattr(attrs, name, None)
                if index is not None:
                    arrays[name] = self.acc.read(index, f"{element}: {name}", normalize=not name.startswith("JOINTS_"))
            count = len(arrays["POSITION"])
            for name, array in arrays.items():
                if len(array) != count:
                    raise fail(self.source, f"{element}: {name}", f"has {len(array)} elements, POSITION has {count}")
            indices = (self.acc.indices(prim.indices, element, count) if prim.indices is not None
                       else np.arange(count, dtype=np.int64))
        if prim.targets:
            arrays = self._morph(arrays, prim.targets, weights, element)
        faces = _triangles(indices, mode)
        positions = arrays["POSITION"][:, :3].astype(np.float64)
        if not np.isfinite(positions).all():
            raise fail(self.source, f"{element}: POSITION", "contains NaN or Inf")
        faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
        if len(faces) == 0:
            return None
        material = self.material(int(prim.material)) if prim.material is not None else None

        def attribute(name: str, width: int) -> np.ndarray | None:
            a = arrays.get(name)
            if a is None:
                return None
            if a.shape[1] < width:
                raise fail(self.source, f"{element}: {name}", f"has {a.shape[1]} components, {width} needed")
            return np.nan_to_num(a[:, :width].astype(np.float64), nan=0.0, posinf=0.0, neginf=0.0)

        normals = attribute("NORMAL", 3)
        tangents = attribute("TANGENT", 4)
        uv0, uv1 = attribute("TEXCOORD_0", 2), attribute("TEXCOORD_1", 2)
        colors = arrays.get("COLOR_0")
        if colors is not None:
            colors = np.nan_to_num(colors.astype(np.float64))
            if colors.shape[1] == 3:
                colors = np.concatenate([colors, np.ones((len(colors), 1))], axis=1)
            elif colors.shape[1] != 4:
                raise fail(self.source, f"{element}: COLOR_0", "must be VEC3 or VEC4")
        origin = np.arange(len(positions))   # each vertex's index in the file (a skin's joints follow it)
        # glTF uvs have v down from the image's top; alight's are OpenGL's (v up from the bottom).
        for uv in (uv0, uv1):
            if uv is not None:
                uv[:, 1] = 1.0 - uv[:, 1]
        if normals is None:
            # Section 3.7.2.1: flat normals, and supplied tangents are then ignored.
            corner = faces.reshape(-1)
            positions, faces = positions[corner], np.arange(len(corner), dtype=np.int64).reshape(-1, 3)
            uv0 = uv0[corner] if uv0 is not None else None
            uv1 = uv1[corner] if uv1 is not None else None
            colors = colors[corner] if colors is not None else None
            origin = origin[corner]
            p = positions[faces]
            face_n, ok = _normalize(cross_rows(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]))
            face_n[~ok] = (0.0, 1.0, 0.0)
            normals = np.repeat(face_n, 3, axis=0)
            tangents = None
        else:
            normals, ok = _normalize(normals)
            if not ok.all():
                from alight.core.mesh import smooth_normals

                computed, computed_ok = _normalize(smooth_normals(positions, faces))
                normals[~ok] = np.where(computed_ok[~ok, None], computed[~ok], (0.0, 1.0, 0.0))
        uvs = uv0 if uv0 is not None else np.zeros((len(positions), 2))
        if uv1 is None and material is not None and any(i.tex_coord == 1 for i in material.textures().values()):
            self.warn(f"uv1:{element}", f"{element}: a texture reads texCoord 1 but there is no TEXCOORD_1; "
                                        f"TEXCOORD_0 is used")
        normal_info = material.normal_texture if material is not None else None
        if normal_info is None:   # a variant's material may have the normal map (KHR_materials_variants)
            normal_info = next((m.normal_texture for m in self.variant_materials(mesh_index, prim_index).values()
                                if m.normal_texture is not None), None)
        if tangents is not None:
            t_xyz, t_ok = _normalize(tangents[:, :3])
            tangents = np.concatenate([t_xyz, np.where(tangents[:, 3:4] < 0, -1.0, 1.0)], axis=1)
            if not t_ok.all():
                tangents = None   # a broken TANGENT: regenerate rather than shade garbage
        if tangents is None and normal_info is not None:
            from alight.core.mikktspace import generate_tangents, split_vertices

            tangent_uv = uv1 if (normal_info.tex_coord == 1 and uv1 is not None) else uvs
            corner_t = generate_tangents(positions, normals, tangent_uv, faces)
            source, faces, tangents = split_vertices(faces, corner_t)
            positions, normals, uvs = positions[source], normals[source], uvs[source]
            uv1 = uv1[source] if uv1 is not None else None
            colors = colors[source] if colors is not None else None
            origin = origin[source]
        # Without TANGENT and a normal map: None, made in world space from the uvs (or any
        # perpendicular where there are none) if a map the user loads needs them (MeshPart.tangents).
        return _Local(positions=positions, normals=normals, uvs=uvs, uvs1=uv1, colors=colors,
                      tangents=None if tangents is None else np.asarray(tangents, np.float64), indices=faces,
                      material=material,
                      joints=_skin_attributes(arrays, "JOINTS", origin),
                      weights=_skin_attributes(arrays, "WEIGHTS", origin))

    def _morph(self, arrays: dict, targets: list, weights: tuple[float, ...], element: str) -> dict:
        """Morph targets at the given weights (glTF 2.0 section 3.7.2.2): each attribute plus
        the weighted sum of its targets' displacements; a weight the file leaves out is 0."""
        out = dict(arrays)
        for t, target in enumerate(targets):
            w = weights[t] if t < len(weights) else 0.0
            if w == 0.0 or not isinstance(target, dict):
                continue
            for name, index in target.items():
                if name not in out or name.startswith(("JOINTS_", "WEIGHTS_")):
                    continue
                delta = self.acc.read(int(index), f"{element}: targets[{t}].{name}")
                base = out[name]
                if len(delta) != len(base):
                    raise fail(self.source, f"{element}: targets[{t}].{name}",
                               f"has {len(delta)} elements, the attribute has {len(base)}")
                width = min(delta.shape[1], base.shape[1], 3)   # a TANGENT's w is no displacement
                moved = base.astype(np.float64)
                moved[:, :width] += w * delta[:, :width].astype(np.float64)
                out[name] = moved
        return out

    def _draco(self, draco: dict, prim, element: str) -> tuple[dict, np.ndarray]:
        """KHR_draco_mesh_compression decoded with DracoPy (Google's Draco library). Each decoded
        attribute holds the values of its glTF accessor's componentType (the extension's rule),
        so it is cast to that type and dequantized when the accessor is ``normalized``, as a
        plain accessor would be (KHR_mesh_quantization's normalized positions and UVs, glTF's
        normalized byte colours)."""
        import DracoPy

        where = f"{element}: KHR_draco_mesh_compression"
        data, start, length, _ = self.acc.view_bytes(draco.get("bufferView"))
        try:
            mesh = DracoPy.decode(data[start:start + length])
        except Exception as exc:
            raise fail(self.source, where, f"cannot decode ({_one_line(exc)})") from None
        by_id = {}
        for attr in getattr(mesh, "attributes", []) or []:
            uid = attr.get("unique_id") if isinstance(attr, dict) else None
            if uid is not None:
                by_id[int(uid)] = np.asarray(attr["data"])
        count = len(np.asarray(mesh.points).reshape(-1, 3))
        arrays = {}
        for name, uid in (draco.get("attributes") or {}).items():
            if name not in _ATTRIBUTES:
                continue
            values = by_id.get(int(uid))
            if values is None:
                raise fail(self.source, where, f"attribute {name} (id {uid}) is not in the Draco data")
            accessor_index = getattr(prim.attributes, name, None)
            arrays[name] = draco_values(values.reshape(count, -1), self._accessor(accessor_index, f"{element}: {name}"),
                                        normalize=not name.startswith("JOINTS_"))
        if "POSITION" not in arrays:
            raise fail(self.source, where, "has no POSITION attribute")
        faces = np.asarray(mesh.faces, np.int64).reshape(-1)
        if len(faces) and (faces.min() < 0 or faces.max() >= count):
            raise fail(self.source, where, f"a face index is out of range ({count} vertices)")
        return arrays, faces

    def _accessor(self, index, element: str):
        accessors = self.doc.accessors or []
        if index is None or not 0 <= int(index) < len(accessors):
            raise fail(self.source, f"{element} (accessors[{index}])", "does not exist")
        return accessors[int(index)]

    # --- the scene --------------------------------------------------------------------------

    def load(self) -> Mesh:
        doc = self.doc
        nodes = doc.nodes or []
        scenes = doc.scenes or []
        if scenes:
            scene_index = doc.scene if doc.scene is not None else 0
            if not 0 <= scene_index < len(scenes):
                raise fail(self.source, "scene", f"scenes[{scene_index}] does not exist")
            roots = list(scenes[scene_index].nodes or [])
        else:
            children = {c for n in nodes for c in (n.children or [])}
            roots = [i for i in range(len(nodes)) if i not in children]
        parts: list[MeshPart] = []
        cameras: list[tuple[int, np.ndarray]] = []
        lights: list[Light] = []
        light_defs = ((doc.extensions or {}).get("KHR_lights_punctual") or {}).get("lights") or []
        visited: set[int] = set()
        worlds: dict[int, np.ndarray] = {}
        placed: list[tuple[int, int, np.ndarray]] = []   # (node, mesh, world), placed once all worlds are known
        instanced: dict[int, np.ndarray] = {}   # node -> its EXT_mesh_gpu_instancing transforms (K, 4, 4)
        hidden = 0   # meshes KHR_node_visibility hides (said when nothing else is drawn)
        stack = [(int(r), np.eye(4), True) for r in reversed(roots)]
        while stack:
            index, parent, visible = stack.pop()
            if not 0 <= index < len(nodes):
                raise fail(self.source, f"nodes[{index}]", "does not exist")
            if index in visited:
                raise fail(self.source, f"nodes[{index}]", "is reached twice (the node hierarchy must be a forest)")
            visited.add(index)
            node = nodes[index]
            world = parent @ _local_matrix(node, self.source, index)
            worlds[index] = world
            # KHR_node_visibility: a node is drawn only if it and every ancestor are visible; its
            # meshes and lights go, its cameras stay (and a hidden skeleton still poses a skin).
            visible = visible and _node_visible(node, self.source, index)
            if node.mesh is not None and not visible:
                hidden += 1
            elif node.mesh is not None:
                placed.append((index, int(node.mesh), world))
                instances = self._instances(node, index)
                if instances is not None:
                    instanced[index] = instances
            if node.camera is not None:
                cameras.append((int(node.camera), world))
            light_ref = (node.extensions or {}).get("KHR_lights_punctual")
            if visible and isinstance(light_ref, dict) and light_ref.get("light") is not None:
                lights.append(self._light(int(light_ref["light"]), light_defs, world))
            for child in reversed(node.children or []):
                stack.append((int(child), world, visible))
        # A model far from the file's origin is moved near it (with its cameras and lights, below)
        # before its positions become float32; a skin's joints move with it.
        origin = far_origin([t for index, _, world in placed for t in
                             ((world @ instanced[index])[:, :3, 3] if index in instanced else [world[:3, 3]])])
        shift = np.eye(4)
        shift[:3, 3] = -origin
        for index, mesh_index, world in placed:
            node = nodes[index]
            name = node.name or f"node{index}"
            weights = self._morph_weights(node, index, mesh_index)
            skin = self._skin_matrices(node, index, worlds) if node.skin is not None else None
            if skin is not None:
                skin = shift @ skin
            instances = instanced.get(index)
            if skin is not None and instances is not None:
                self.warn(f"instanced-skin:{index}", f"nodes[{index}]: EXT_mesh_gpu_instancing on a skinned mesh; "
                                                     f"drawn once, as its skin places it")
                instances = None
            parts.extend(self._place(mesh_index, shift @ world, name, weights, skin, instances))
        if doc.animations:
            n = len(doc.animations)
            self.warn("animations", f"animations: {n} animation{'s' if n != 1 else ''} not played; "
                                    f"the rest pose the nodes give is drawn")
        if not parts:
            if hidden and not placed:
                raise AlightError(f"{self.source}: every node that places a mesh is hidden (KHR_node_visibility "
                                  f"visible false on it or an ancestor): nothing to draw")
            if doc.meshes and not placed:   # (the meshes' accessors were never read: say what is missing)
                n = len(doc.meshes)
                where = f" of scenes[{scene_index}]" if scenes else ""
                raise AlightError(f"{self.source}: no node places a mesh: {n} mesh{'es' if n != 1 else ''} but no "
                                  f"node{where} names one (glTF draws what a scene's nodes place)")
            raise AlightError(f"{self.source}: no triangles in the file")
        for light in lights:
            if light.kind != "directional":
                light.vector = tuple(float(x) for x in np.asarray(light.vector, np.float64) - origin)
        mesh = Mesh(parts, self.source, lights=lights, warnings=self.warnings, origin=tuple(map(float, origin)),
                    animations=len(doc.animations or []), variants=list(self.variants))
        mesh.cameras = [self._camera(i, shift @ world, mesh) for i, world in cameras]
        return mesh

    def _instances(self, node, index: int) -> np.ndarray | None:
        """A node's EXT_mesh_gpu_instancing transforms (K, 4, 4), each T * R * S of its
        TRANSLATION, ROTATION (xyzw) and SCALE accessors (any subset; all of the same count), or
        None when the node has no such attributes. The mesh is drawn once per instance, under
        node_world * instance; attributes named with a leading underscore are the application's
        and are ignored."""
        ext = (node.extensions or {}).get("EXT_mesh_gpu_instancing")
        if not isinstance(ext, dict):
            return None
        where = f"nodes[{index}].extensions.EXT_mesh_gpu_instancing"
        attributes = ext.get("attributes")
        if not isinstance(attributes, dict):
            raise fail(self.source, where, "attributes must be an object of accessor indices")
        widths = {"TRANSLATION": 3, "ROTATION": 4, "SCALE": 3}
        values = {}
        for name, width in widths.items():
            accessor = attributes.get(name)
            if accessor is None:
                continue
            element = f"{where}.attributes.{name}"
            acc = self._accessor(accessor, element)
            if acc.componentType != 5126 and not (name == "ROTATION" and acc.normalized):
                raise fail(self.source, element, "must be FLOAT" + (" or a normalized BYTE or SHORT"
                                                                    if name == "ROTATION" else ""))
            array = self.acc.read(int(accessor), element).astype(np.float64)
            if array.shape[1] != width:
                raise fail(self.source, element, f"must be VEC{width}")
            if not np.isfinite(array).all():
                raise fail(self.source, element, "contains NaN or Inf")
            values[name] = array
        if not values:
            return None
        counts = {name: len(a) for name, a in values.items()}
        if len(set(counts.values())) > 1:
            said = ", ".join(f"{name} {n}" for name, n in counts.items())
            raise fail(self.source, where, f"the attributes' accessors must have one count; they have {said}")
        count = next(iter(counts.values()))
        return _trs_matrices(values.get("TRANSLATION", np.zeros((count, 3))),
                             values.get("ROTATION", np.tile([0.0, 0.0, 0.0, 1.0], (count, 1))),
                             values.get("SCALE", np.ones((count, 3))))

    def _morph_weights(self, node, index: int, mesh_index: int) -> tuple[float, ...]:
        """The morph weights a node draws its mesh with: node.weights, else mesh.weights."""
        meshes = self.doc.meshes or []
        mesh = meshes[mesh_index] if 0 <= mesh_index < len(meshes) else None
        weights = node.weights if node.weights is not None else (mesh.weights if mesh is not None else None)
        if weights is None:
            return ()
        try:
            values = tuple(float(w) for w in weights)
        except (TypeError, ValueError):
            raise fail(self.source, f"nodes[{index}]", "weights must be numbers") from None
        if not all(map(math.isfinite, values)):
            raise fail(self.source, f"nodes[{index}]", "weights contain NaN or Inf")
        return values

    def _node_world(self, index: int, worlds: dict[int, np.ndarray]) -> np.ndarray:
        """A node's world matrix, from the scene's walk or, for a joint outside it, its parents'."""
        if index in worlds:
            return worlds[index]
        nodes = self.doc.nodes or []
        if not 0 <= index < len(nodes):
            raise fail(self.source, f"nodes[{index}]", "does not exist")
        parents = getattr(self, "_parents", None)
        if parents is None:
            parents = self._parents = {int(c): i for i, n in enumerate(nodes) for c in (n.children or [])}
        chain, i = [], index
        while i is not None and i not in worlds and i not in chain:
            chain.append(i)
            i = parents.get(i)
        world = worlds[i] if i in worlds else np.eye(4)
        for j in reversed(chain):
            world = world @ _local_matrix(nodes[j], self.source, j)
            worlds[j] = world
        return worlds[index]

    def _skin_matrices(self, node, index: int, worlds: dict[int, np.ndarray]) -> np.ndarray:
        """(J, 4, 4) joint matrices of a node's skin (glTF 2.0 section 3.7.3): each joint's world
        matrix times its inverse bind matrix. The skinned node's own transform takes no part."""
        skins = self.doc.skins or []
        where = f"nodes[{index}].skin"
        if not 0 <= int(node.skin) < len(skins):
            raise fail(self.source, where, f"skins[{node.skin}] does not exist")
        skin = skins[int(node.skin)]
        joints = [int(j) for j in (skin.joints or [])]
        if not joints:
            raise fail(self.source, f"skins[{node.skin}]", "has no joints")
        if skin.inverseBindMatrices is not None:
            ibm = self.acc.read(int(skin.inverseBindMatrices), f"skins[{node.skin}].inverseBindMatrices")
            if ibm.shape != (len(joints), 16):
                raise fail(self.source, f"skins[{node.skin}].inverseBindMatrices",
                           f"must be {len(joints)} MAT4 (one a joint)")
            ibm = ibm.astype(np.float64).reshape(-1, 4, 4).transpose(0, 2, 1)   # column-major
        else:
            ibm = np.broadcast_to(np.eye(4), (len(joints), 4, 4))
        mats = np.stack([self._node_world(j, worlds) for j in joints]) @ ibm
        if not np.isfinite(mats).all():
            raise fail(self.source, f"skins[{node.skin}]", "a joint matrix contains NaN or Inf")
        return mats

    def _skinned(self, local: _Local, joint_mats: np.ndarray, element: str) -> np.ndarray | None:
        """(N, 4, 4) per-vertex skinning matrices: sum_k WEIGHTS[k] * joint_mats[JOINTS[k]]."""
        if not local.joints or len(local.joints) != len(local.weights):
            self.warn(f"skin:{element}", f"{element}: a skinned mesh without matching JOINTS_n and WEIGHTS_n; "
                                         f"drawn with its node's transform")
            return None
        per_vertex = np.zeros((len(local.positions), 4, 4))
        for joints, weights in zip(local.joints, local.weights):
            j = np.asarray(joints, np.int64)
            if len(j) and (j.min() < 0 or j.max() >= len(joint_mats)):
                raise fail(self.source, f"{element}: JOINTS", f"joint {int(j.max())} is out of range "
                                                              f"(the skin has {len(joint_mats)} joints)")
            w = np.asarray(weights, np.float64)
            per_vertex += np.einsum("nk,nkij->nij", w, joint_mats[j])
        return per_vertex

    def _place(self, mesh_index: int, world: np.ndarray, name: str, weights: tuple[float, ...] = (),
               skin: np.ndarray | None = None, instances: np.ndarray | None = None) -> list[MeshPart]:
        """A mesh's primitives as world-space parts: under ``world``, under each vertex's skinning
        matrix (``skin``), or once per instance under ``world @ instances[k]`` (EXT_mesh_gpu_instancing:
        each part then holds every instance's copy, transformed in one batch)."""
        meshes = self.doc.meshes or []
        if instances is not None and not len(instances):
            return []
        if not 0 <= mesh_index < len(meshes):
            raise fail(self.source, f"meshes[{mesh_index}]", "does not exist")
        if not np.isfinite(world).all():
            raise fail(self.source, f"meshes[{mesh_index}]", "its node transform contains NaN or Inf")
        out = []
        for p in range(len(meshes[mesh_index].primitives or [])):
            local = self.primitive(mesh_index, p, weights)
            if local is None:
                continue
            element = f"meshes[{mesh_index}].primitives[{p}]"
            per_vertex = self._skinned(local, skin, element) if skin is not None else None
            group = per_vertex is None and instances is not None   # one (K, 3, 3) per instance
            if group:
                mats = world[None] @ instances
                m, t = mats[:, :3, :3], mats[:, :3, 3]
            elif per_vertex is None:
                m, t = world[None, :3, :3], world[None, :3, 3]
            else:
                m, t = per_vertex[:, :3, :3], per_vertex[:, :3, 3]
            # Normals take the cofactor matrix (det * inverse transpose) times sign(det); a
            # mirroring transform also reverses the winding (section 3.7.4) and the bitangent.
            cof = np.stack([np.cross(m[:, 1], m[:, 2]), np.cross(m[:, 2], m[:, 0]), np.cross(m[:, 0], m[:, 1])], axis=1)
            det = np.einsum("ni,ni->n", m[:, 0], cof[:, 0])
            sign = np.where(det < 0, -1.0, 1.0)
            faces = local.indices
            n = len(local.positions)
            if group:   # instance k's vertices follow instance k-1's; a mirroring one reverses its winding
                faces = np.where((sign < 0)[:, None, None], faces[None, :, ::-1], faces[None])
                faces = (faces + (np.arange(len(sign)) * n)[:, None, None]).reshape(-1, 3)
            elif len(sign) == 1:
                faces = faces[:, ::-1] if sign[0] < 0 else faces
            else:
                faces = np.where((sign[faces[:, 0]] < 0)[:, None], faces[:, ::-1], faces)
            cof = cof * sign[:, None, None]
            # A node without a transform (most big scans) keeps the decoded arrays as they are:
            # their normals are unit already (_decode_primitive), and each pass over millions of
            # float64 rows costs a fraction of a second and its copy.
            identity = per_vertex is None and not group and np.array_equal(world, np.eye(4))
            copies = len(sign) if group else 1
            if not group:
                positions, normals, tangents = _moved(local, m, t, cof, sign, identity)
            else:
                # Instances a batch at a time, each batch one vectorised transform of every array,
                # so its float64 temporaries stay in the cache: 2000 instances of 1225 vertices
                # load in 1.3 s here, where all at once took 6.0 s and 2000 plain nodes take 1.8 s.
                positions, normals = np.empty((copies * n, 3), np.float32), np.empty((copies * n, 3), np.float32)
                tangents = None if local.tangents is None else np.empty((copies * n, 4), np.float32)
                step = max(1, INSTANCE_BATCH_VERTICES // max(n, 1))
                for a in range(0, copies, step):
                    b = min(a + step, copies)
                    rows = slice(a * n, b * n)
                    positions[rows], normals[rows], batch_tangents = _moved(local, m[a:b], t[a:b], cof[a:b],
                                                                             sign[a:b], False, instanced=True)
                    if tangents is not None:
                        tangents[rows] = batch_tangents

            def tiled(a: np.ndarray | None) -> np.ndarray | None:
                return None if a is None else np.ascontiguousarray(np.tile(a, (copies, 1)) if group else a,
                                                                   dtype=np.float32)

            out.append(MeshPart(
                name=f"{name}.{p}" if len(meshes[mesh_index].primitives) > 1 else name,
                positions=np.ascontiguousarray(positions, dtype=np.float32),
                normals=np.ascontiguousarray(normals, dtype=np.float32),
                uvs=tiled(local.uvs),
                tangents=tangents,
                indices=np.ascontiguousarray(faces, dtype=np.uint32),
                material=local.material,
                uvs1=tiled(local.uvs1),
                colors=tiled(local.colors),
                element=element,
            ))
            choices = self.variant_materials(mesh_index, p)
            if choices:
                out[-1].variant_materials = {None: local.material, **choices}
        return out

    def _camera(self, index: int, world: np.ndarray, mesh: Mesh) -> Camera:
        cams = self.doc.cameras or []
        where = f"cameras[{index}]"
        if not 0 <= index < len(cams):
            raise fail(self.source, where, "does not exist")
        cam = cams[index]
        position = world[:3, 3]
        forward, _ = _normalize(-world[:3, 2])
        up, _ = _normalize(world[:3, 1])
        centre, radius = mesh.bounding_sphere()
        reach = float(np.linalg.norm(position - centre)) + 2.0 * radius
        if cam.type == "orthographic" and cam.orthographic is not None:
            o = cam.orthographic
            near, far = float(o.znear or 0.0), float(o.zfar or reach)
            return Camera(tuple(position), tuple(position + forward), tuple(up), 35.0, near=near,
                          far=max(far, near + 1e-6), ortho_half_height=abs(float(o.ymag or 1.0)))
        p = cam.perspective
        if p is None or p.yfov is None or not p.yfov > 0:
            raise fail(self.source, where, "perspective.yfov is missing or not positive")
        near = float(p.znear) if p.znear else 0.01
        far = float(p.zfar) if p.zfar else max(reach, near * 10.0)
        return Camera(tuple(position), tuple(position + forward), tuple(up), math.degrees(float(p.yfov)),
                      near=near, far=far)

    def _light(self, index: int, defs: list, world: np.ndarray) -> Light:
        where = f"extensions.KHR_lights_punctual.lights[{index}]"
        if not 0 <= index < len(defs) or not isinstance(defs[index], dict):
            raise fail(self.source, where, "does not exist")
        d = defs[index]
        kind = d.get("type")
        if kind not in ("point", "directional", "spot"):
            raise fail(self.source, where, f"type {kind!r} is not point, directional or spot")
        color = tuple(float(x) for x in d.get("color", (1.0, 1.0, 1.0)))
        intensity = float(d.get("intensity", 1.0))
        direction, _ = _normalize(-world[:3, 2])
        position = world[:3, 3]
        light = Light(kind=kind, vector=tuple(direction) if kind == "directional" else tuple(position),
                      color=color, intensity=intensity, direction=tuple(direction))  # type: ignore[arg-type]
        if d.get("range") is not None and kind != "directional":
            light.range = float(d["range"])
        if kind == "spot":
            spot = d.get("spot") or {}
            light.inner_cone_deg = math.degrees(float(spot.get("innerConeAngle", 0.0)))
            light.outer_cone_deg = math.degrees(float(spot.get("outerConeAngle", math.pi / 4)))
        return light


def _apply(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N, 3) vectors times (1, 3, 3) one matrix or (N, 3, 3) one a vertex."""
    return rows_times(v, m[0]) if len(m) == 1 else np.einsum("nij,nj->ni", m, v)


def _variant_names(doc, source: str) -> list[str]:
    """KHR_materials_variants' variant names, in the file's order ([] without the extension)."""
    ext = (doc.extensions or {}).get("KHR_materials_variants")
    if ext is None:
        return []
    variants = ext.get("variants") if isinstance(ext, dict) else None
    if not isinstance(variants, list):
        raise fail(source, "extensions.KHR_materials_variants", "variants must be a list")
    names = []
    for i, v in enumerate(variants):
        if not isinstance(v, dict) or not isinstance(v.get("name"), str):
            raise fail(source, f"extensions.KHR_materials_variants.variants[{i}]", "has no name")
        names.append(v["name"])
    return names


def gltf_variant_names(path: str | os.PathLike) -> list[str]:
    """A glTF file's KHR_materials_variants names from its JSON alone (no accessor or image is
    read): how alight batch checks --variant against each mesh before rendering."""
    doc, _ = read_document(Path(path), str(path))
    return _variant_names(doc, str(path))


def _moved(local: _Local, m: np.ndarray, t: np.ndarray, cof: np.ndarray, sign: np.ndarray, identity: bool,
           instanced: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """A primitive's positions, normals and tangents (float32) under ``m`` and ``t``: one matrix
    (1, 3, 3), one a vertex (N, 3, 3), or with ``instanced`` one an instance (K, 3, 3), the copies
    one after another. ``cof``: the normals' matrices (cofactors times sign(det)); ``sign``: the
    determinants' signs, which flip the bitangent (w) of a mirrored copy."""
    move = _apply_each if instanced else _apply
    if identity:
        normals = local.normals
    else:
        normals, ok = _normalize(move(cof, local.normals))
        normals[~ok] = (0.0, 1.0, 0.0)
    tangents = None
    if local.tangents is not None:
        t_xyz, t_ok = _normalize(move(m, local.tangents[:, :3]))
        t_xyz = t_xyz - normals * np.sum(normals * t_xyz, axis=1, keepdims=True)
        t_xyz, t_ok = _normalize(t_xyz)
        if not t_ok.all():
            axis = np.where((np.abs(normals[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
            fallback, _ = _normalize(axis - normals * np.sum(normals * axis, axis=1, keepdims=True))
            t_xyz[~t_ok] = fallback[~t_ok]
        w = ((local.tangents[None, :, 3:4] * sign[:, None, None]).reshape(-1, 1) if instanced
             else local.tangents[:, 3:4] * sign[:, None])
        tangents = np.ascontiguousarray(np.concatenate([t_xyz, w], axis=1), dtype=np.float32)
    if identity:
        positions = local.positions
    elif instanced:
        positions = move(m, local.positions) + np.repeat(t, len(local.positions), axis=0)
    else:
        positions = _apply(m, local.positions) + t
    return (np.ascontiguousarray(positions, dtype=np.float32), np.ascontiguousarray(normals, dtype=np.float32),
            tangents)


def _apply_each(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(N, 3) vectors under each of (K, 3, 3) matrices: (K * N, 3), instance k's rows k*N.. (K+1)*N-1."""
    # (a stacked matmul: 0.12 ms for 26 x 1225 rows here, where rows_times' broadcasting took 2 ms)
    return (np.asarray(v, np.float64) @ m.transpose(0, 2, 1)).reshape(-1, 3)


def _trs_matrices(t: np.ndarray, q: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(K, 4, 4) matrices T * R * S from (K, 3) translations, (K, 4) xyzw quaternions (normalized
    here; a zero one is the identity) and (K, 3) scales, as _local_matrix makes one."""
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    q = np.where(norm > 0, q / np.where(norm > 0, norm, 1.0), [0.0, 0.0, 0.0, 1.0])
    x, y, z, w = q.T
    r = np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)
    out = np.tile(np.eye(4), (len(t), 1, 1))
    out[:, :3, :3] = r * s[:, None, :]
    out[:, :3, 3] = t
    return out


def _missing_image_file(base: Path, uri: str) -> Path | None:
    """The path a relative image URI names when no file is there (None: a data: URI, or present)."""
    import urllib.parse

    if uri.startswith("data:"):
        return None
    parsed = urllib.parse.urlsplit(uri)
    if parsed.scheme and len(parsed.scheme) > 1:
        return None              # read_uri refuses it with its own line
    path = base / urllib.parse.unquote(parsed.path)
    return None if path.exists() else path


def _json_slot(slot: str) -> str:
    if slot in LAYER_TEXTURES:
        return "extensions.{}.{}".format(*LAYER_TEXTURES[slot])
    return {"base_color": "pbrMetallicRoughness.baseColorTexture",
            "metallic_roughness": "pbrMetallicRoughness.metallicRoughnessTexture",
            "normal": "normalTexture", "emissive": "emissiveTexture", "occlusion": "occlusionTexture"}[slot]


def _triangles(indices: np.ndarray, mode: int) -> np.ndarray:
    """Triangles (M, 3) of a primitive's index list (section 3.7.2.1's topology table)."""
    n = len(indices)
    if mode == 4:
        return indices[: n - n % 3].reshape(-1, 3)
    if n < 3:
        return np.zeros((0, 3), np.int64)
    i = np.arange(n - 2)
    if mode == 5:   # TRIANGLE_STRIP: p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}
        return np.stack([indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]], axis=1)
    # TRIANGLE_FAN: p_i = {v_{i+1}, v_{i+2}, v_0}
    return np.stack([indices[i + 1], indices[i + 2], np.full_like(i, indices[0])], axis=1)


def _node_visible(node, source: str, index: int) -> bool:
    """KHR_node_visibility's ``visible`` (default true) on one node; not a boolean: refused."""
    ext = (node.extensions or {}).get("KHR_node_visibility")
    if not isinstance(ext, dict) or "visible" not in ext:
        return True
    if not isinstance(ext["visible"], bool):
        raise fail(source, f"nodes[{index}].extensions.KHR_node_visibility.visible",
                   f"must be true or false, not {ext['visible']!r}")
    return ext["visible"]


def _local_matrix(node, source: str, index: int) -> np.ndarray:
    """A node's local transform (section 3.5.3): its column-major matrix, or T * R * S."""
    if node.matrix is not None:
        m = np.asarray(node.matrix, np.float64)
        if m.shape != (16,):
            raise fail(source, f"nodes[{index}].matrix", "must have 16 numbers")
        return m.reshape(4, 4).T
    t = np.asarray(node.translation if node.translation is not None else (0.0, 0.0, 0.0), np.float64)
    q = np.asarray(node.rotation if node.rotation is not None else (0.0, 0.0, 0.0, 1.0), np.float64)
    s = np.asarray(node.scale if node.scale is not None else (1.0, 1.0, 1.0), np.float64)
    if t.shape != (3,) or q.shape != (4,) or s.shape != (3,):
        raise fail(source, f"nodes[{index}]", "translation, rotation or scale has the wrong length")
    norm = np.linalg.norm(q)
    x, y, z, w = q / norm if norm > 0 else (0.0, 0.0, 0.0, 1.0)
    r = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    out = np.eye(4)
    out[:3, :3] = r * s[None, :]
    out[:3, 3] = t
    return out


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 160 else text[:157] + "..."


def load_gltf(path: Path, spec: str) -> Mesh:
    """A .gltf/.glb file as world-space parts with its cameras, lights and warnings."""
    return _Reader(path, spec).load()


def gltf_image(path: str | os.PathLike, index: int) -> np.ndarray:
    """The file's ``images[index]`` decoded as (H, W, 4) uint8 (alight.exchange.images.decode_texture):
    how a material read from a .glb names its maps (``FILE.glb#images[N]``). Errors: one line
    naming the file and the image."""
    p = Path(path)
    if not p.is_file():
        raise AlightError(f"{p}: no such file")
    reader = _Reader(p, str(p))
    reader._decode_images([int(index)])
    return reader._images[int(index)]

"""A material with its maps written as glTF 2.0: ``.gltf`` (JSON, its images and buffer beside
it as files) or ``.glb`` (one file), optionally with a mesh (UVs and tangents included).

The maps are ``alight.core.texture_maps.TextureMaps``; what goes out is what alight draws:

    base_color, emissive            -> baseColorTexture, emissiveTexture (sRGB PNG)
    normal (normal_dx: green flipped) -> normalTexture (OpenGL convention, as glTF defines)
    occlusion                       -> occlusionTexture (R)
    metallic_roughness              -> metallicRoughnessTexture (G roughness, B metal)
    metallic, roughness (greyscale; roughness_gloss: inverted)
                                    -> packed into that one image's B and G (a channel with no
                                       map is 255, so its factor alone acts, as in the shader)
    uv_scale, uv_offset             -> KHR_texture_transform on every textureInfo

Images are written as PNG with the 8-bit values alight decoded (no re-encoding loss), so a file
written here renders the same pixels through ``alight render --mesh`` (the file's material) and
``--preset`` (alight.exchange.material_files). The factors come from
``alight.exchange.gltf_material.material_to_gltf``. With ``file_materials`` each part of a mesh
file keeps its own material instead (alight.exchange.gltf_file_materials: textures, samplers,
texCoord and KHR_texture_transform as loaded; TEXCOORD_1 and COLOR_0 go out with the parts).
Every file is written atomically; the
.gltf's JSON last, so a failure never leaves a document pointing at missing files.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import struct
from pathlib import Path
from typing import Any

import numpy as np

from alight.core.material import Material
from alight.core.texture_maps import TextureMaps
from alight.errors import AlightError
from alight.exchange.gltf_material import GLB_BIN, GLB_JSON, GLB_MAGIC, material_to_gltf
from alight.exchange.output import atomic_path, check_output_path

EXT_TRANSFORM = "KHR_texture_transform"
# glTF sampler: LINEAR, LINEAR_MIPMAP_LINEAR, REPEAT: how alight samples a user's maps.
SAMPLER = {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}


def _png(image: np.ndarray, channels: int) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    pixels = np.ascontiguousarray(image[:, :, :channels])
    Image.fromarray(pixels, "RGB" if channels == 3 else "RGBA").save(buf, "PNG")
    return buf.getvalue()


def _resized(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    from PIL import Image

    if image.shape[1::-1] == size:
        return image
    return np.asarray(Image.fromarray(np.ascontiguousarray(image[:, :, :3]), "RGB").resize(size, Image.BILINEAR))


def map_images(maps: TextureMaps) -> tuple[dict[str, np.ndarray], list[str]]:
    """The glTF slots' images (slot -> (H, W, 3|4) uint8) for ``maps``, and one-line notes on
    what was converted. Separate metallic/roughness maps are packed into one image (B metal,
    G roughness; R the occlusion where an occlusion map of the same size exists, else 255)."""
    from alight.exchange.texture_sets import load_slot_image

    decoded = {slot: load_slot_image(maps, slot) for slot in maps.paths()}
    out = {s: decoded[s] for s in ("base_color", "normal", "emissive", "occlusion", "metallic_roughness") if s in decoded}
    notes = []
    if "metallic" in decoded or "roughness" in decoded:
        parts = [decoded[s] for s in ("metallic_roughness", "metallic", "roughness") if s in decoded]
        size = max((p.shape[1], p.shape[0]) for p in parts)
        if any(p.shape[1::-1] != size for p in parts):
            notes.append(f"metallic and roughness maps of different sizes resized to {size[0]}x{size[1]} to pack them")
        packed = (_resized(decoded["metallic_roughness"], size)[:, :, :3].copy() if "metallic_roughness" in decoded
                  else np.full((size[1], size[0], 3), 255, np.uint8))
        if "roughness" in decoded:
            packed[:, :, 1] = _resized(decoded["roughness"], size)[:, :, 0]
        if "metallic" in decoded:
            packed[:, :, 2] = _resized(decoded["metallic"], size)[:, :, 0]
        out["metallic_roughness"] = packed
        notes.append("separate metallic and roughness maps packed into one metallicRoughness image (G rough, B metal)")
    return out, notes


def _texture_info(maps: TextureMaps, index: int) -> dict:
    info: dict[str, Any] = {"index": index}
    if tuple(maps.uv_scale) != (1.0, 1.0) or tuple(maps.uv_offset) != (0.0, 0.0):
        (su, sv), (ou, ov) = maps.uv_scale, maps.uv_offset
        # alight tiles OpenGL uvs (v up): uv * scale + offset. In glTF's (v down) that is the same
        # scale with offset (ou, 1 - sv - ov) (v_gltf = 1 - v_gl on both sides).
        info["extensions"] = {EXT_TRANSFORM: {"offset": [float(ou), float(1.0 - sv - ov)], "scale": [float(su), float(sv)]}}
    return info


class _Builder:
    """The document and its binary data as they grow (buffer views 4-byte aligned)."""

    def __init__(self, m: Material):
        gm, used = material_to_gltf(m)
        self.material = gm
        self.used = set(used)
        self.blob = bytearray()
        self.doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": "alight"}}
        self.views: list[dict] = []
        self.accessors: list[dict] = []
        self.images: list[dict] = []
        self.textures: list[dict] = []
        self.files: dict[str, bytes] = {}     # image files beside a .gltf: name -> bytes
        self.samplers: list[dict] = []
        self.materials: list[dict] = []
        self._by_hash: dict[tuple[str, int], int] = {}
        self._images_by_hash: dict[str, int] = {}
        self._encoded: dict[int, tuple[bytes, str]] = {}   # id(decoded image) -> (bytes, mimeType): once each

    def view(self, data: bytes, target: int | None = None) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        view: dict[str, Any] = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        self.blob.extend(data)
        return len(self.views) - 1

    def accessor(self, array: np.ndarray, component: int, kind: str, target: int, bounds: bool) -> int:
        acc: dict[str, Any] = {"bufferView": self.view(np.ascontiguousarray(array).tobytes(), target),
                               "componentType": component, "type": kind,
                               "count": int(array.shape[0]) if kind != "SCALAR" else int(array.size)}
        if bounds:
            acc["min"] = [float(x) for x in array.min(axis=0)]
            acc["max"] = [float(x) for x in array.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def sampler(self, sampler: dict) -> int:
        if sampler not in self.samplers:
            self.samplers.append(dict(sampler))
        return self.samplers.index(sampler)

    def texture(self, data: bytes, name: str, glb: bool, sampler: dict = SAMPLER, mime: str = "image/png") -> int:
        """A texture for this encoded image (PNG or JPEG) and sampler (one image per distinct
        content, one texture per image and sampler)."""
        digest = hashlib.sha1(data).hexdigest()
        if digest not in self._images_by_hash:
            if glb:
                self.images.append({"bufferView": self.view(data), "mimeType": mime})
            else:
                self.files[name] = data
                self.images.append({"uri": name})
            self._images_by_hash[digest] = len(self.images) - 1
        key = (digest, self.sampler(sampler))
        if key not in self._by_hash:
            self.textures.append({"sampler": key[1], "source": self._images_by_hash[digest]})
            self._by_hash[key] = len(self.textures) - 1
        return self._by_hash[key]

    def file_texture(self, info, stem: str, glb: bool) -> int:
        """A texture for a mesh file's TextureInfo with its sampler as loaded: the file's own
        PNG or JPEG bytes where they still decode to the pixels drawn, else those pixels as PNG
        (RGB where every alpha is 255). ``stem``: the image file's name without its suffix."""
        from alight.exchange.gltf_file_materials import gltf_sampler

        encoded = self._encoded.get(id(info.image))
        if encoded is None:
            encoded = _as_loaded(info) or (_png(info.image, 3 if bool((info.image[:, :, 3] == 255).all()) else 4),
                                           "image/png")
            self._encoded[id(info.image)] = encoded
        data, mime = encoded
        suffix = ".jpg" if mime == "image/jpeg" else ".png"
        return self.texture(data, stem + suffix, glb, gltf_sampler(info.sampler), mime)


def _as_loaded(info) -> tuple[bytes, str] | None:
    """(the file's bytes, their mimeType) where ``info.encoded`` decodes to ``info.image`` (a
    decode is much cheaper than a PNG encode of the same pixels); else None."""
    return _encoded_if_same(info.encoded, info.image, "export")


def _encoded_if_same(data: bytes | None, image: np.ndarray, where: str, rgb: bool = False) -> tuple[bytes, str] | None:
    """(``data``, its mimeType) where the PNG or JPEG bytes decode to ``image`` (``rgb``: to its
    RGB, with every alpha 255, as a map exported as RGB), else None."""
    from alight.exchange.gltf import JPEG_MAGIC, PNG_MAGIC, decode_image

    if not data or not (data[:8] == PNG_MAGIC or data[:3] == JPEG_MAGIC):
        return None
    try:
        decoded = decode_image(data, where)
    except AlightError:
        return None
    if rgb:
        same = (decoded.shape[:2] == image.shape[:2] and bool((decoded[:, :, 3] == 255).all())
                and np.array_equal(decoded[:, :, :3], image[:, :, :3]))
    else:
        same = np.array_equal(decoded, image)
    return (data, "image/jpeg" if data[:3] == JPEG_MAGIC else "image/png") if same else None


def _map_file(path: str | None, image: np.ndarray) -> tuple[bytes, str] | None:
    """(the map file's bytes, their mimeType) where the file is a PNG or JPEG that decodes to the
    RGB drawn with every alpha 255, so a JPEG map stays the JPEG it was (a PNG re-encode of a
    2048^2 photo map is several times its size and slow); None for a converted map (normal_dx,
    gloss, a packed metallic-roughness), an image inside a glTF file, or any other format."""
    if not path or "#images[" in path:
        return None
    try:
        data = Path(path).read_bytes()
    except OSError:
        return None
    return _encoded_if_same(data, image, path, rgb=True)


def _add_maps(b: _Builder, maps: TextureMaps, stem: str, glb: bool) -> list[str]:
    images, notes = map_images(maps)
    if not images:
        return notes
    gm, pbr = b.material, b.material["pbrMetallicRoughness"]
    for slot in ("base_color", "metallic_roughness", "normal", "occlusion", "emissive"):
        if slot not in images:
            continue
        data, mime = _map_file(getattr(maps, slot, None), images[slot]) or (_png(images[slot], 3), "image/png")
        suffix = ".jpg" if mime == "image/jpeg" else ".png"
        index = b.texture(data, f"{stem}_{slot}{suffix}", glb, mime=mime)
        info = _texture_info(maps, index)
        if slot == "base_color":
            pbr["baseColorTexture"] = info
        elif slot == "metallic_roughness":
            pbr["metallicRoughnessTexture"] = info
        else:
            gm[f"{slot}Texture"] = info
    if any("extensions" in info for info in _infos(gm)):
        b.used.add(EXT_TRANSFORM)
    return notes


def _infos(gm: dict) -> list[dict]:
    pbr = gm.get("pbrMetallicRoughness", {})
    return [x for x in (pbr.get("baseColorTexture"), pbr.get("metallicRoughnessTexture"), gm.get("normalTexture"),
                        gm.get("occlusionTexture"), gm.get("emissiveTexture")) if x]


def _unit(v: np.ndarray) -> np.ndarray:
    v = np.asarray(v, np.float64)
    n = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _tangents(normals: np.ndarray, tangents: np.ndarray) -> np.ndarray:
    """(N, 4) float32 unit tangents with w = +-1, as the validator checks: a zero or parallel
    tangent (a pole) is replaced by any direction orthogonal to the normal."""
    t = np.asarray(tangents, np.float64)[:, :3]
    t = t - normals * np.sum(t * normals, axis=1, keepdims=True)
    bad = np.linalg.norm(t, axis=1) < 1e-6
    if bad.any():
        axis = np.where(np.abs(normals[bad, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        t[bad] = np.cross(normals[bad], axis)
    w = np.where(np.asarray(tangents, np.float64)[:, 3] < 0.0, -1.0, 1.0)
    return np.concatenate([_unit(t), w[:, None]], axis=1).astype(np.float32)


def _add_file_materials(b: _Builder, mesh, stem: str, glb: bool) -> list[int]:
    """Each part's material index: its own material (one glTF material per distinct
    FileMaterial, in the parts' order), the panel's for a part without one, as drawn."""
    from alight.exchange.gltf_file_materials import file_material_to_gltf

    index: dict[int, int] = {}   # id(FileMaterial) or id(None) (the panel's, added on first use) -> index
    out = []
    for part in mesh.parts:
        fm = part.material
        if fm is None:
            if id(None) not in index:
                b.materials.append(b.material)
                index[id(None)] = len(b.materials) - 1
            out.append(index[id(None)])
            continue
        if id(fm) not in index:
            n = len(b.materials)
            gm, used = file_material_to_gltf(
                fm, lambda info, slot: b.file_texture(info, f"{stem}_m{n}_{slot}", glb))
            b.used.update(used)
            b.materials.append(gm)
            index[id(fm)] = n
        out.append(index[id(fm)])
    return out


def _add_mesh(b: _Builder, mesh, materials: list[int] | None = None, extra: bool = False) -> None:
    """The parts as one node each (world space); ``materials``: each part's material index (None:
    0); ``extra``: TEXCOORD_1 and COLOR_0 too where a part has them (a file's materials read them)."""
    meshes, nodes = [], []
    for i, part in enumerate(mesh.parts):
        positions = np.asarray(part.positions, np.float32)
        normals = _unit(part.normals)
        uvs = np.asarray(part.uvs, np.float32).copy()
        uvs[:, 1] = 1.0 - uvs[:, 1]   # alight's uvs are OpenGL's (v up); glTF's v runs down
        attrs = {"POSITION": b.accessor(positions, 5126, "VEC3", 34962, True),
                 "NORMAL": b.accessor(normals.astype(np.float32), 5126, "VEC3", 34962, False),
                 "TANGENT": b.accessor(_tangents(normals, part.tangents), 5126, "VEC4", 34962, False),
                 "TEXCOORD_0": b.accessor(uvs, 5126, "VEC2", 34962, False)}
        if extra and part.uvs1 is not None:
            uvs1 = np.asarray(part.uvs1, np.float32).copy()
            uvs1[:, 1] = 1.0 - uvs1[:, 1]
            attrs["TEXCOORD_1"] = b.accessor(uvs1, 5126, "VEC2", 34962, False)
        if extra and part.colors is not None:
            attrs["COLOR_0"] = b.accessor(np.asarray(part.colors, np.float32), 5126, "VEC4", 34962, False)
        idx = b.accessor(np.asarray(part.indices, np.uint32).reshape(-1), 5125, "SCALAR", 34963, False)
        material = materials[i] if materials is not None else 0
        meshes.append({"name": part.name, "primitives": [{"attributes": attrs, "indices": idx, "material": material}]})
        nodes.append({"name": part.name, "mesh": len(meshes) - 1})
    b.doc.update({"scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes})


def export_gltf(material: Material, path: str | os.PathLike, maps: TextureMaps | None = None,
                mesh=None, file_materials: bool = False) -> tuple[Path, list[str]]:
    """Write ``material`` with ``maps`` (and ``mesh``, an alight.core.mesh.Mesh, when given)
    to ``path`` (.gltf: images ``STEM_SLOT.png`` and ``STEM.bin`` beside it; .glb: one file).
    ``file_materials``: each part of ``mesh`` keeps the material the mesh file gave it (its
    textures, samplers, transforms; alight.exchange.gltf_file_materials), as the view draws with
    the file's own materials on; ``material`` and ``maps`` then go only on parts without one
    (images ``STEM_mN_SLOT.png``). Returns the path and one-line notes on what was converted or
    left out. Errors: AlightError naming the file (an unwritable folder, a map that does not read)."""
    out = check_output_path(path, (".gltf", ".glb"))
    glb = out.suffix.lower() == ".glb"
    b = _Builder(material)
    own = file_materials and mesh is not None and any(p.material is not None for p in mesh.parts)
    needs_panel = not own or any(p.material is None for p in mesh.parts)
    notes = _add_maps(b, maps or TextureMaps(), out.stem, glb) if needs_panel else []
    if not needs_panel:
        b.used.clear()   # the panel's material is not written: its extensions are not used
    if not own:
        b.materials.append(b.material)
    if mesh is not None:
        _add_mesh(b, mesh, _add_file_materials(b, mesh, out.stem, glb) if own else None, extra=own)
        notes += _left_out(mesh) if own else []
    while len(b.blob) % 4:
        b.blob.append(0)
    doc = b.doc
    doc["materials"] = b.materials
    if b.used:
        doc["extensionsUsed"] = sorted(b.used)
    for key, value in (("accessors", b.accessors), ("bufferViews", b.views), ("images", b.images),
                       ("samplers", b.samplers), ("textures", b.textures)):
        if value:
            doc[key] = value
    if b.blob:
        doc["buffers"] = [{"byteLength": len(b.blob)} if glb else {"byteLength": len(b.blob), "uri": f"{out.stem}.bin"}]
    try:
        if glb:
            _write(out, _glb(doc, bytes(b.blob)))
        else:
            for name, data in b.files.items():
                _write(out.with_name(name), data)
            if b.blob:
                _write(out.with_name(f"{out.stem}.bin"), bytes(b.blob))
            _write(out, (json.dumps(doc, indent=1) + "\n").encode("utf-8"))
    except OSError as e:
        raise AlightError(f"{out}: cannot write ({e.strerror or e})") from None
    return out, notes


def _left_out(mesh) -> list[str]:
    """What a mesh file brought that the export does not write (the parts go out in world space,
    one node each)."""
    what = [f"{len(x)} {name}{'s' if len(x) > 1 else ''}" for x, name in
            ((mesh.cameras, "camera"), (mesh.lights, "light")) if x]
    animations = getattr(mesh, "animations", 0)
    if animations:      # (the parts go out in the pose drawn, the rest pose)
        what.append(f"{animations} animation{'s' if animations > 1 else ''}")
    return [f"the mesh file's {' and '.join(what)} left out"] if what else []


def export_mesh_glb(mesh, m: Material, path: str | os.PathLike) -> Path:
    """Every part of an alight.core.mesh.Mesh (world space) as one node each, all with material
    ``m`` (factors only), as .glb: positions, normals, tangents and uvs."""
    return export_gltf(m, check_output_path(path, (".glb",)), None, mesh)[0]


def _glb(doc: dict, blob: bytes) -> bytes:
    json_bytes = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    json_bytes += b" " * (-len(json_bytes) % 4)   # chunks are 4-byte aligned; JSON pads with spaces
    chunks = [struct.pack("<II", len(json_bytes), GLB_JSON), json_bytes]
    if blob:
        chunks += [struct.pack("<II", len(blob), GLB_BIN), blob]
    body = b"".join(chunks)
    return struct.pack("<III", GLB_MAGIC, 2, 12 + len(body)) + body


def _write(out: Path, data: bytes) -> None:
    with atomic_path(out) as tmp:
        tmp.write_bytes(data)

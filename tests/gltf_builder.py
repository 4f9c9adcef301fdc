"""Small glTF 2.0 files written by the tests themselves (tmp_path): a plain builder of buffers,
accessors, images, materials and nodes, so each test states exactly what its file holds."""

from __future__ import annotations

import base64
import io
import json
import struct
from pathlib import Path

import numpy as np

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125
BYTE, SHORT = 5120, 5122
_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}


class Gltf:
    def __init__(self):
        self.doc: dict = {"asset": {"version": "2.0", "generator": "alight tests"}, "scene": 0,
                          "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "accessors": [],
                          "bufferViews": [], "buffers": [], "materials": []}
        self.blob = bytearray()

    def _view(self, data: bytes, stride: int | None = None) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if stride:
            view["byteStride"] = stride
        self.blob.extend(data)
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, component: int = FLOAT, normalized: bool = False, bounds: bool = False,
                 sparse: tuple | None = None, view: int | None = None) -> int:
        """An accessor over ``array`` (N, k) stored as ``component``; ``sparse``: (indices, values)
        substituted over it (``array`` then the dense base, or None for all zeros)."""
        dtype = {FLOAT: np.float32, UBYTE: np.uint8, USHORT: np.uint16, UINT: np.uint32, BYTE: np.int8,
                 SHORT: np.int16}[component]
        a = np.asarray(array)
        a = a.reshape(len(a), -1) if a.ndim > 1 else a.reshape(-1, 1)
        acc = {"componentType": component, "count": len(a), "type": _TYPES[a.shape[1]]}
        if normalized:
            acc["normalized"] = True
        if view is not None:
            acc["bufferView"] = view
        elif not (sparse is not None and np.all(a == 0)):
            acc["bufferView"] = self._view(np.ascontiguousarray(a.astype(dtype)).tobytes())
        if bounds:   # of the values after sparse substitution, as the specification requires
            effective = a.astype(np.float64).copy()
            if sparse is not None:
                effective[np.asarray(sparse[0])] = np.asarray(sparse[1]).reshape(len(sparse[0]), -1)
            acc["min"] = [float(x) for x in effective.min(axis=0)]
            acc["max"] = [float(x) for x in effective.max(axis=0)]
        if sparse is not None:
            idx, values = sparse
            values = np.asarray(values).reshape(len(idx), -1)
            acc["sparse"] = {"count": len(idx),
                             "indices": {"bufferView": self._view(np.asarray(idx, np.uint16).tobytes()),
                                         "componentType": USHORT},
                             "values": {"bufferView": self._view(np.ascontiguousarray(values.astype(dtype)).tobytes())}}
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def image(self, rgba: np.ndarray, sampler: dict | None = None) -> int:
        """A PNG texture of an (H, W, 3|4) uint8 array; returns the texture index."""
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(np.asarray(rgba, np.uint8)).save(buf, format="PNG")
        self.doc.setdefault("images", []).append({"bufferView": self._view(buf.getvalue()), "mimeType": "image/png"})
        tex = {"source": len(self.doc["images"]) - 1}
        if sampler is not None:
            self.doc.setdefault("samplers", []).append(sampler)
            tex["sampler"] = len(self.doc["samplers"]) - 1
        self.doc.setdefault("textures", []).append(tex)
        return len(self.doc["textures"]) - 1

    def material(self, **fields) -> int:
        self.doc["materials"].append(fields)
        return len(self.doc["materials"]) - 1

    def mesh(self, primitives: list[dict], **node) -> int:
        self.doc["meshes"].append({"primitives": primitives})
        self.doc["nodes"].append({"mesh": len(self.doc["meshes"]) - 1, **node})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def node(self, **fields) -> int:
        self.doc["nodes"].append(fields)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def use(self, *extensions: str, required: bool = False) -> None:
        used = self.doc.setdefault("extensionsUsed", [])
        used.extend(e for e in extensions if e not in used)
        if required:
            req = self.doc.setdefault("extensionsRequired", [])
            req.extend(e for e in extensions if e not in req)

    def save(self, path: Path, embedded: bool = True) -> Path:
        """A .glb, or a .gltf with the buffer as a data: URI (or beside it as ``name.bin``)."""
        path = Path(path)
        doc = json.loads(json.dumps(self.doc))
        if not doc["materials"]:
            del doc["materials"]
        blob = bytes(self.blob) + b"\0" * (-len(self.blob) % 4)
        if path.suffix == ".glb":
            doc["buffers"] = [{"byteLength": len(blob)}]
            text = json.dumps(doc).encode()
            text += b" " * (-len(text) % 4)
            total = 12 + 8 + len(text) + 8 + len(blob)
            path.write_bytes(struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A)
                             + text + struct.pack("<II", len(blob), 0x004E4942) + blob)
        elif embedded:
            doc["buffers"] = [{"byteLength": len(blob),
                               "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
            path.write_text(json.dumps(doc))
        else:
            (path.parent / (path.stem + ".bin")).write_bytes(blob)
            doc["buffers"] = [{"byteLength": len(blob), "uri": path.stem + ".bin"}]
            path.write_text(json.dumps(doc))
        return path


def grid_plane(n: int = 4, size: float = 2.0):
    """An n x n grid in the XY plane facing +Z: positions (V, 3), normals, glTF uvs (v down),
    triangle indices (M, 3) counter-clockwise from +Z."""
    t = np.linspace(0.0, 1.0, n + 1)
    u, v = np.meshgrid(t, t, indexing="xy")
    positions = np.stack([(u - 0.5) * size, (0.5 - v) * size, np.zeros_like(u)], -1).reshape(-1, 3)
    uvs = np.stack([u, v], -1).reshape(-1, 2)
    normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
    idx = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            idx += [(a, c, b), (b, c, d)]
    return positions, normals, uvs, np.array(idx)


def checker(cells: int = 8, size: int = 64, colours=((200, 20, 30), (240, 240, 240))) -> np.ndarray:
    y, x = np.mgrid[0:size, 0:size]
    on = ((x * cells // size) + (y * cells // size)) % 2 == 0
    return np.where(on[..., None], np.array(colours[0], np.uint8), np.array(colours[1], np.uint8))

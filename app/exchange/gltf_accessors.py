"""glTF 2.0 buffers and accessors as numpy arrays (glTF 2.0 sections 3.6 "Buffers and Buffer
Views" and 3.6.2 "Accessors").

Handled as the specification says: interleaved views (``byteStride``), every component type,
``normalized`` integers (section 3.11, the dequantisation ``f = max(c / (2^(b-1) - 1), -1)`` and
``f = c / (2^b - 1)``), which KHR_mesh_quantization relies on, sparse accessors (section 3.6.2.3,
with or without a ``bufferView`` underneath), and buffer URIs that are relative,
percent-encoded (RFC 3986) or ``data:`` URIs. A bufferView compressed with
EXT_meshopt_compression (or its KHR_ successor) is decoded by meshoptimizer's own decoder (PyPI
``meshopt``, a binding of its C++ sources) the first time an accessor reads it; its filters
(octahedral, quaternion, exponential, colour) are undone by the same call. Every problem is an AlightError naming the file
and the element (``accessors[4]``, ``buffers[0]``).
"""

from __future__ import annotations

import base64
import binascii
import urllib.parse
from pathlib import Path

import numpy as np

from alight.errors import AlightError

COMPONENT_TYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
TYPE_SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
INDEX_TYPES = (5121, 5123, 5125)
MESHOPT = ("EXT_meshopt_compression", "KHR_meshopt_compression")
_MESHOPT_MODES = ("ATTRIBUTES", "TRIANGLES", "INDICES")
_MESHOPT_FILTERS = ("NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL", "COLOR")


def meshopt_available() -> bool:
    try:
        import meshopt  # noqa: F401
    except ImportError:
        return False
    return True


def fail(source: str, element: str, problem: str) -> AlightError:
    """``<file>: <element>: <problem>`` as one line."""
    return AlightError(" ".join(f"{source}: {element}: {problem}".split()))


def read_uri(source: str, base: Path, uri: str, element: str) -> bytes:
    """The bytes a glTF URI names: a ``data:`` URI (base64) or a path relative to the file's
    folder, percent-decoded (``base%20color.png`` is ``base color.png``)."""
    if uri.startswith("data:"):
        header, _, payload = uri.partition(",")
        if not header.endswith(";base64"):
            return urllib.parse.unquote_to_bytes(payload)
        try:
            return base64.b64decode(payload, validate=False)
        except (binascii.Error, ValueError) as e:
            raise fail(source, element, f"bad base64 data URI ({e})") from None
    parsed = urllib.parse.urlsplit(uri)
    if parsed.scheme and len(parsed.scheme) > 1:   # a Windows drive letter is no scheme
        raise fail(source, element, f"URI '{uri}' is not a relative path or a data: URI")
    path = base / urllib.parse.unquote(parsed.path)
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise fail(source, element, f"'{uri}' not found ({path})") from None
    except OSError as e:
        raise fail(source, element, f"cannot read '{uri}' ({e.strerror or e})") from None


class Accessors:
    """Decodes a glTF document's accessors (its JSON objects read as attributes), reading each
    buffer once.

    ``glb_blob``: the GLB binary chunk (buffer 0 without a URI), or None.
    """

    def __init__(self, doc, source: str, base: Path, glb_blob: bytes | None):
        self.doc, self.source, self.base, self.glb_blob = doc, source, base, glb_blob
        self._buffers: dict[int, bytes] = {}
        self._decoded: dict[int, bytes] = {}   # meshopt-compressed bufferViews, decoded once

    def buffer(self, index: int) -> bytes:
        data = self._buffers.get(index)
        if data is None:
            buffers = self.doc.buffers or []
            if not 0 <= index < len(buffers):
                raise fail(self.source, f"buffers[{index}]", "does not exist")
            buf = buffers[index]
            if buf.uri is None:
                if index != 0 or self.glb_blob is None:
                    raise fail(self.source, f"buffers[{index}]", "has no uri and there is no GLB binary chunk")
                data = self.glb_blob
            else:
                data = read_uri(self.source, self.base, buf.uri, f"buffers[{index}]")
            if buf.byteLength is not None and len(data) < buf.byteLength:
                raise fail(self.source, f"buffers[{index}]", f"holds {len(data)} bytes, byteLength says {buf.byteLength}")
            self._buffers[index] = data
        return data

    def view_bytes(self, index: int) -> tuple[bytes, int, int, int | None]:
        """(buffer bytes, view start, view length, byteStride) of bufferViews[index]."""
        views = self.doc.bufferViews or []
        if index is None or not 0 <= index < len(views):
            raise fail(self.source, f"bufferViews[{index}]", "does not exist")
        view = views[index]
        extensions = view.extensions or {}
        compressed = next((extensions[n] for n in MESHOPT if isinstance(extensions.get(n), dict)), None)
        if compressed is not None and meshopt_available():
            data = self._meshopt(index, compressed)
            return data, 0, len(data), view.byteStride
        data = self.buffer(view.buffer)
        start, length = int(view.byteOffset or 0), int(view.byteLength or 0)
        if start + length > len(data):
            raise fail(self.source, f"bufferViews[{index}]", f"bytes {start}..{start + length} lie past the end "
                                                             f"of buffers[{view.buffer}] ({len(data)} bytes)")
        return data, start, length, view.byteStride

    def _meshopt(self, index: int, ext: dict) -> bytes:
        """bufferViews[index]'s data decoded from its EXT_meshopt_compression stream:
        ``count`` elements of ``byteStride`` bytes (the extension's decoder interface)."""
        data = self._decoded.get(index)
        if data is not None:
            return data
        import meshopt

        where = f"bufferViews[{index}].extensions.EXT_meshopt_compression"
        try:
            source, start, length = int(ext["buffer"]), int(ext.get("byteOffset") or 0), int(ext["byteLength"])
            count, stride = int(ext["count"]), int(ext["byteStride"])
        except (KeyError, TypeError, ValueError):
            raise fail(self.source, where, "needs buffer, byteLength, byteStride and count") from None
        mode, filt = ext.get("mode"), ext.get("filter") or "NONE"
        if mode not in _MESHOPT_MODES:
            raise fail(self.source, where, f"mode {mode!r} is not ATTRIBUTES, TRIANGLES or INDICES")
        if filt not in _MESHOPT_FILTERS:
            raise fail(self.source, where, f"filter {filt!r} is not a meshopt filter")
        blob = self.buffer(source)
        if start + length > len(blob):
            raise fail(self.source, where, f"bytes {start}..{start + length} lie past the end of buffers[{source}]")
        try:
            rows = meshopt.decode_gltf_buffer(blob[start:start + length], count, stride, mode,
                                              None if filt == "NONE" else filt)
        except (ValueError, RuntimeError) as exc:
            raise fail(self.source, where, f"cannot decode ({' '.join(str(exc).split())})") from None
        if mode != "ATTRIBUTES":   # the decoder gives index values; the view holds them as stride-byte ints
            rows = np.asarray(rows).astype({2: np.uint16, 4: np.uint32}.get(stride, np.uint32))
        data = self._decoded[index] = np.ascontiguousarray(rows).tobytes()
        return data

    def _strided(self, element: str, view_index: int, offset: int, count: int, dtype, width: int,
                 allow_stride: bool = True) -> np.ndarray:
        """(count, width) of dtype from a view, honouring its byteStride."""
        data, start, length, stride = self.view_bytes(view_index)
        item = np.dtype(dtype).itemsize
        element_size = item * width
        stride = int(stride) if (stride and allow_stride) else element_size
        if stride < element_size:
            raise fail(self.source, element, f"byteStride {stride} of bufferViews[{view_index}] is smaller than "
                                             f"one element ({element_size} bytes)")
        if offset % item:
            raise fail(self.source, element, f"byteOffset {offset} is not a multiple of the component size {item}")
        end = offset + (stride * (count - 1) + element_size if count else 0)
        if end > length:
            raise fail(self.source, element, f"reads {end} bytes of bufferViews[{view_index}], which holds {length}")
        if count == 0:
            return np.zeros((0, width), dtype)
        array = np.ndarray((count, width), dtype=np.dtype(dtype).newbyteorder("<"), buffer=data,
                           offset=start + offset, strides=(stride, item))
        return np.array(array, dtype=dtype)   # a copy: the buffer is shared and read-only

    def read(self, index: int, element: str | None = None, normalize: bool = True) -> np.ndarray:
        """accessors[index] as a (count, components) array: float32 for float and normalized
        accessors (when ``normalize``), else its integer type. Sparse substitution applied."""
        accessors = self.doc.accessors or []
        where = f"accessors[{index}]" if element is None else f"{element} (accessors[{index}])"
        if index is None or not 0 <= index < len(accessors):
            raise fail(self.source, where, "does not exist")
        acc = accessors[index]
        dtype = COMPONENT_TYPES.get(acc.componentType)
        width = TYPE_SIZES.get(acc.type)
        if dtype is None:
            raise fail(self.source, where, f"unknown componentType {acc.componentType}")
        if width is None:
            raise fail(self.source, where, f"unknown type {acc.type!r}")
        if acc.type in ("MAT2", "MAT3") and np.dtype(dtype).itemsize < 4:
            raise fail(self.source, where, f"{acc.type} of {np.dtype(dtype).name} (column padding) is not supported")
        count = int(acc.count or 0)
        if acc.bufferView is None:
            values = np.zeros((count, width), dtype)   # all zeros unless sparse fills some in
        else:
            values = self._strided(where, acc.bufferView, int(acc.byteOffset or 0), count, dtype, width)
        sparse = acc.sparse
        if sparse is not None and sparse.count:
            n = int(sparse.count)
            idx_type = COMPONENT_TYPES.get(sparse.indices.componentType)
            if sparse.indices.componentType not in INDEX_TYPES:
                raise fail(self.source, where, f"sparse indices componentType {sparse.indices.componentType} "
                                               f"is not an unsigned integer type")
            ids = self._strided(f"{where} sparse.indices", sparse.indices.bufferView,
                                int(sparse.indices.byteOffset or 0), n, idx_type, 1, allow_stride=False)[:, 0]
            values_ref = sparse["values"]   # not sparse.values: that is the dict method
            new = self._strided(f"{where} sparse.values", values_ref.get("bufferView"),
                                int(values_ref.get("byteOffset") or 0), n, dtype, width, allow_stride=False)
            if n and int(ids.max()) >= count:
                raise fail(self.source, where, f"sparse index {int(ids.max())} is out of range (count {count})")
            values = values.copy() if not values.flags.writeable else values
            values[ids.astype(np.int64)] = new
        if normalize and values.dtype != np.float32:
            if acc.normalized:
                values = dequantize(values)
            else:
                values = values.astype(np.float32)
        return values

    def indices(self, index: int, element: str, vertex_count: int) -> np.ndarray:
        """A primitive's index accessor as int64 (count,), checked against the vertex count."""
        acc = (self.doc.accessors or [None])[index] if index is not None and 0 <= index < len(self.doc.accessors or []) else None
        if acc is None:
            raise fail(self.source, f"{element}: indices (accessors[{index}])", "does not exist")
        if acc.componentType not in INDEX_TYPES or acc.type != "SCALAR":
            raise fail(self.source, f"{element}: indices (accessors[{index}])",
                       "must be SCALAR of unsigned byte, short or int")
        values = self.read(index, f"{element}: indices", normalize=False)[:, 0].astype(np.int64)
        if len(values) and int(values.max()) >= vertex_count:
            raise fail(self.source, f"{element}: indices (accessors[{index}])",
                       f"index {int(values.max())} is out of range ({vertex_count} vertices)")
        return values


def dequantize(values: np.ndarray) -> np.ndarray:
    """Normalized integers to float32 (glTF 2.0 section 3.11, "Animations"'s table, which
    KHR_mesh_quantization and the core's normalized attributes share)."""
    info = np.iinfo(values.dtype)
    if info.min == 0:
        return (values.astype(np.float32) / np.float32(info.max)).astype(np.float32)
    return np.maximum(values.astype(np.float32) / np.float32(info.max), np.float32(-1.0))
